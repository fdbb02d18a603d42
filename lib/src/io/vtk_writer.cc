// WriteVtu (vtk_writer.h).
#include "diffpd/vtk_writer.h"

#include <fstream>
#include <set>
#include <sstream>

#include "diffpd/error.h"
#include "mesh/hex_node_order.h"

namespace diffpd {
namespace {

constexpr int kVtkTetra = 10;
constexpr int kVtkHexahedron = 12;

void CheckPointData(const std::string& path, int n, const VtkPointData& point_data) {
  std::set<std::string> names;
  for (const auto& [name, values] : point_data) {
    std::ostringstream s;
    s << "WriteVtu('" << path << "'): point data '" << name << "' ";
    if (name.empty() || name.find_first_of("\"&<>',") != std::string::npos) {
      throw InvalidInputError(s.str() + "has an empty name or one with a character of \" & < > ' ,");
    }
    if (!names.insert(name).second) throw InvalidInputError(s.str() + "appears twice");
    if ((values.rows() != 1 && values.rows() != 3) || values.cols() != n) {
      s << "is " << values.rows() << " x " << values.cols() << ", must be 1 x " << n << " or 3 x " << n;
      throw InvalidInputError(s.str());
    }
  }
}

void WriteArray(std::ostream& out, const std::string& attributes, const Eigen::MatrixXd& values) {
  out << "        <DataArray type=\"Float64\"" << attributes << " NumberOfComponents=\"" << values.rows()
      << "\" format=\"ascii\">\n";
  for (int v = 0; v < values.cols(); ++v) {
    out << "         ";
    for (int c = 0; c < values.rows(); ++c) out << ' ' << values(c, v);
    out << '\n';
  }
  out << "        </DataArray>\n";
}

}  // namespace

void WriteVtu(const std::string& path, const Mesh& mesh, const Eigen::Matrix3Xd& positions,
              const VtkPointData& point_data) {
  const int n = mesh.num_vertices();
  const int k = NodesPerElement(mesh.type);
  if (positions.cols() != n) {
    std::ostringstream s;
    s << "WriteVtu('" << path << "'): positions has " << positions.cols() << " columns, the mesh has " << n
      << " vertices";
    throw InvalidInputError(s.str());
  }
  if (mesh.elements.rows() != k) {
    throw InvalidInputError("WriteVtu('" + path + "'): elements must have " + std::to_string(k) + " rows for " +
                            ToString(mesh.type));
  }
  CheckPointData(path, n, point_data);
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << mesh.num_elements() << "\">\n"
      << "      <PointData>\n";
  for (const auto& [name, values] : point_data) WriteArray(out, " Name=\"" + name + "\"", values);
  out << "      </PointData>\n      <Points>\n";
  WriteArray(out, "", positions);
  out << "      </Points>\n      <Cells>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int e = 0; e < mesh.num_elements(); ++e) {
    out << "         ";
    for (int b = 0; b < k; ++b) {  // VTK node b
      out << ' ' << mesh.elements(mesh.type == ElementType::kHex8 ? internal::kOursHexNodeOfGmsh[b] : b, e);
    }
    out << '\n';
  }
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (int e = 0; e < mesh.num_elements(); ++e) out << "          " << static_cast<long>(e + 1) * k << '\n';
  out << "        </DataArray>\n"
      << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  const int cell_type = mesh.type == ElementType::kTet4 ? kVtkTetra : kVtkHexahedron;
  for (int e = 0; e < mesh.num_elements(); ++e) out << "          " << cell_type << '\n';
  out << "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  out.close();
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
}

}  // namespace diffpd
