// PvdWriter (vtk_writer.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/vtk_writer.h"

namespace diffpd {

PvdWriter::PvdWriter(std::string directory, std::string basename)
    : directory_(std::move(directory)), basename_(std::move(basename)) {
  if (basename_.empty() || basename_.find('/') != std::string::npos) {
    throw InvalidInputError("PvdWriter: basename '" + basename_ + "' must be a non-empty file name without '/'");
  }
  std::error_code error;
  std::filesystem::create_directories(directory_, error);
  if (error || !std::filesystem::is_directory(directory_)) {
    throw InvalidInputError("PvdWriter: cannot create directory '" + directory_ + "'" +
                            (error ? ": " + error.message() : std::string()));
  }
}

void PvdWriter::AddFrame(double time, const Mesh& mesh, const Eigen::Matrix3Xd& positions,
                         const VtkPointData& point_data) {
  if (!std::isfinite(time) || (!frames_.empty() && !(time > frames_.back().first))) {
    std::ostringstream s;
    s << "PvdWriter::AddFrame: time = " << time << " s, must be finite";
    if (!frames_.empty()) s << " and > the previous frame's time " << frames_.back().first << " s";
    throw InvalidInputError(s.str());
  }
  char number[32];
  std::snprintf(number, sizeof(number), "_%04d.vtu", num_frames());
  const std::string file = basename_ + number;
  WriteVtu((std::filesystem::path(directory_) / file).string(), mesh, positions, point_data);
  frames_.emplace_back(time, file);
}

void PvdWriter::Write() const {
  const std::string path = (std::filesystem::path(directory_) / (basename_ + ".pvd")).string();
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (const auto& [time, file] : frames_) {
    out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  }
  out << "  </Collection>\n</VTKFile>\n";
  out.close();
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
}

}  // namespace diffpd
