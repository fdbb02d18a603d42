#include "calibration/starfish_plot.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/vtk_writer.h"
#include "tools/tradeoff.h"

namespace diffpd::problems {

void WriteStarfishTracePlot(const std::string& trace_csv, const std::string& png_path, const std::string& title) {
  if (!GnuplotAvailable()) throw std::runtime_error("gnuplot is not on PATH: no plot " + png_path);
  const std::string data = GnuplotQuote(trace_csv);
  std::ostringstream s;
  s << "set terminal pngcairo size 1400,1200 font ',10'\n"
    << "set output " << GnuplotQuote(png_path) << "\n"
    << "set termoption noenhanced\n"
    << "set datafile separator ','\n"
    << "set key top left horizontal font ',8'\n"
    << "set grid\n"
    << "set y2tics\nset ytics nomirror\n"
    << "set multiplot layout 4,2 title " << GnuplotQuote(title) << "\n";
  // Columns: 1 time, 2 tendon, 3 activation, then per marker m (0-based)
  // 4 + 4m sim x, 5 + 4m cap x, 6 + 4m sim z, 7 + 4m cap z.
  for (int m = 0; m < 4; ++m)
    for (int axis = 0; axis < 2; ++axis) {
      const int sim = 4 + 4 * m + 2 * axis, cap = sim + 1;
      const char* name = axis == 0 ? "x" : "z";
      s << "set ylabel 'M" << m + 1 << " " << name << " displacement (mm)'\n"
        << "set y2label 'tendon (mm)'\n"
        << (m == 3 ? "set xlabel 'time (s)'\n" : "unset xlabel\n") << "plot " << data
        << " every ::1 using 1:2 axes x1y2 with lines lc rgb '#c8c8c8' title 'tendon', " << data
        << " every ::1 using 1:" << cap << " with lines lw 2 lc rgb '#1f77b4' title 'captured', " << data
        << " every ::1 using 1:" << sim << " with lines lw 2 lc rgb '#d62728' title 'simulated'\n";
    }
  s << "unset multiplot\n";
  RunGnuplot(s.str(), png_path);
}

namespace {

// One poly-data file of points (one vertex cell each) with a vector field.
void WritePoints(const std::string& path, const Eigen::Matrix3Xd& points, const std::string& field,
                 const Eigen::Matrix3Xd& values) {
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
  out << std::setprecision(17);
  const Eigen::Index n = points.cols();
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<PolyData>\n<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n << "\">\n"
      << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < n; ++i) out << points(0, i) << " " << points(1, i) << " " << points(2, i) << "\n";
  out << "</DataArray>\n</Points>\n<Verts>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < n; ++i) out << i << (i + 1 < n ? " " : "\n");
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < n; ++i) out << i + 1 << (i + 1 < n ? " " : "\n");
  out << "</DataArray>\n</Verts>\n<PointData Vectors=\"" << field << "\">\n<DataArray type=\"Float64\" Name=\"" << field
      << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < n; ++i) out << values(0, i) << " " << values(1, i) << " " << values(2, i) << "\n";
  out << "</DataArray>\n</PointData>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
}

}  // namespace

std::array<std::string, 2> WriteStarfishVtk(const std::string& dir, const std::string& stem, const Mesh& mesh,
                                            const std::array<int, 4>& marker_vertices, const std::vector<State>& states,
                                            int substeps, const std::vector<double>& frame_times,
                                            const StarfishDisplacements& captured, int stride) {
  if (stride < 1) throw InvalidInputError("stride = " + std::to_string(stride) + " is invalid: must be >= 1");
  const int frames = static_cast<int>(captured.size());
  if (static_cast<int>(frame_times.size()) != frames)
    throw InvalidInputError("starfish vtk: " + std::to_string(frame_times.size()) + " frame times for " +
                            std::to_string(frames) + " frames");
  if (frames == 0 || static_cast<int>(states.size()) < (frames - 1) * substeps + 1)
    throw InvalidInputError("starfish vtk: " + std::to_string(states.size()) + " states are too few for " +
                            std::to_string(frames) + " frames of " + std::to_string(substeps) + " steps");
  PvdWriter body(dir, stem + "_body");
  std::filesystem::create_directories(dir);
  std::vector<std::pair<double, std::string>> marker_files;
  const Eigen::Matrix3Xd rest = Eigen::Map<const Eigen::Matrix3Xd>(states[0].x.data(), 3, mesh.num_vertices());
  for (int f = 0; f < frames; f += stride) {
    const double t = frame_times[f] - frame_times[0];
    const Eigen::Map<const Eigen::Matrix3Xd> x(states[f * substeps].x.data(), 3, mesh.num_vertices());
    body.AddFrame(t, mesh, x, {{"displacement", x - rest}});
    Eigen::Matrix3Xd points(3, 4), error(3, 4);
    for (int m = 0; m < 4; ++m) {
      points.col(m) = rest.col(marker_vertices[m]);
      points(0, m) += captured[f][m](0);
      points(2, m) += captured[f][m](1);
      error.col(m) = x.col(marker_vertices[m]) - points.col(m);
      error(1, m) = 0;  // y is not observed
    }
    std::ostringstream name;
    name << stem << "_markers_" << std::setw(4) << std::setfill('0') << marker_files.size() << ".vtp";
    WritePoints((std::filesystem::path(dir) / name.str()).string(), points, "simulated_error", error);
    marker_files.emplace_back(t, name.str());
  }
  body.Write();
  const std::string markers = (std::filesystem::path(dir) / (stem + "_markers.pvd")).string();
  std::ofstream out(markers);
  if (!out) throw InvalidInputError("cannot write '" + markers + "'");
  out << std::setprecision(17)
      << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<Collection>\n";
  for (const auto& [t, file] : marker_files)
    out << "<DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  out << "</Collection>\n</VTKFile>\n";
  if (!out) throw InvalidInputError("cannot write '" + markers + "'");
  return {(std::filesystem::path(dir) / (stem + "_body.pvd")).string(), markers};
}

}  // namespace diffpd::problems
