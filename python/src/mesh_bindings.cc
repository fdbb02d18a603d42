// Meshes, their readers and generators, boundary extraction and VTK output
// (diffpd/mesh.h, box_mesh.h, gmsh_io.h, tetgen_io.h, surface_mesh.h,
// voxelizer.h, state_forces.h's and quad_hydrodynamics.h's boundary helpers,
// vtk_writer.h). Mesh.vertices (3 x n, float64) and Mesh.elements (k x m,
// int32) are views of the mesh's own memory.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/box_mesh.h"
#include "diffpd/gmsh_io.h"
#include "diffpd/mesh.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/state_forces.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/tetgen_io.h"
#include "diffpd/voxelizer.h"
#include "diffpd/vtk_writer.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {

void BindMesh(py::module_& m) {
  LibraryNames(py::enum_<ElementType>(m, "ElementType", "Linear tetrahedra (TET4) or trilinear hexahedra (HEX8).")
                   .value("TET4", ElementType::kTet4)
                   .value("HEX8", ElementType::kHex8));
  m.def("nodes_per_element", &NodesPerElement, "type"_a, "Nodes of an element type (4 or 8).");

  py::class_<Mesh> mesh(m, "Mesh",
                        "A volumetric mesh (diffpd/mesh.h): node order conventions are checked by validate.");
  mesh.def(py::init<>())
      .def(py::init([](ElementType type, const Eigen::Matrix3Xd& vertices, const Eigen::MatrixXi& elements) {
             return Mesh{type, vertices, elements};
           }),
           "type"_a, "vertices"_a, "elements"_a)
      .def_readwrite("type", &Mesh::type);
  EigenMember(mesh, "vertices", &Mesh::vertices, "3 x n rest positions (m); a view of the mesh's memory");
  EigenMember(mesh, "elements", &Mesh::elements, "k x m node indices (int32), one column per element; a view");
  mesh.def_property_readonly("num_vertices", &Mesh::num_vertices)
      .def_property_readonly("num_elements", &Mesh::num_elements)
      .def_property_readonly("num_dofs", &Mesh::num_dofs)
      .def(
          "validate", [](const Mesh& self, const std::string& what) { ValidateMesh(self, what); }, "what"_a = "mesh",
          "Raises InvalidInputError naming the first violation (diffpd/mesh.h lists them).")
      .def("signed_element_volume", &SignedElementVolume, "positions"_a, "element"_a,
           "Signed volume of one element at positions (3 x n).")
      .def("__repr__", [](const Mesh& self) {
        return "<diffpd.Mesh " + std::string(ToString(self.type)) + ", " + std::to_string(self.num_vertices()) +
               " vertices, " + std::to_string(self.num_elements()) + " elements>";
      });
  m.def("validate_mesh", &ValidateMesh, "mesh"_a, "what"_a = "mesh");
  m.def("make_box_hex_mesh", &MakeBoxHexMesh, "cells"_a, "size"_a, "origin"_a = Vec3(Vec3::Zero()),
        "cells[0] x cells[1] x cells[2] hexahedra spanning [origin, origin + size] (diffpd/box_mesh.h).");
  m.def("read_gmsh", &ReadGmsh, "path"_a, "A Gmsh .msh file (diffpd/gmsh_io.h).");
  m.def("read_tetgen", &ReadTetGen, "node_path"_a, "ele_path"_a, "TetGen .node/.ele files (diffpd/tetgen_io.h).");

  py::class_<SurfaceMesh> surface(m, "SurfaceMesh", "A triangle surface (diffpd/surface_mesh.h).");
  surface.def(py::init<>());
  EigenMember(surface, "vertices", &SurfaceMesh::vertices, "3 x n positions; a view");
  EigenMember(surface, "triangles", &SurfaceMesh::triangles, "3 x t vertex indices (int32); a view");
  m.def("read_obj", &ReadObj, "path"_a, "The triangles of a Wavefront OBJ file.");
  m.def("winding_number", &WindingNumber, "surface"_a, "point"_a);
  m.def("enclosed_volume", &EnclosedVolume, "surface"_a);
  m.def("validate_watertight", &ValidateWatertight, "surface"_a, "what"_a = "surface");
  m.def("tetrahedralize_surface", &TetrahedralizeSurface, "surface"_a, "switches"_a = "pq1.414Y", "scale"_a = 1.0,
        "Tet mesh of a closed surface by the tetgen program (diffpd/tetgen_io.h).");
  m.def("voxelize_surface", &VoxelizeSurface, "surface"_a, "dx"_a, "scale"_a = 1.0);
  m.def("voxelize_sdf", &VoxelizeSdf, "sdf"_a, "origin"_a, "cells"_a, "dx"_a,
        "Hexes of the cells whose centre c has sdf(c) < 0 (sdf: a callable on a length-3 array).");

  m.def("boundary_triangles", &BoundaryTriangles, "mesh"_a, "3 x t outward boundary triangles.");
  m.def("boundary_nodes", &BoundaryNodes, "mesh"_a);
  m.def("boundary_quads", &BoundaryQuads, "mesh"_a, "4 x F boundary faces of a hex mesh.");

  m.def("write_vtu", &WriteVtu, "path"_a, "mesh"_a, "positions"_a, "point_data"_a = VtkPointData{},
        "One VTK unstructured-grid file; point_data: list of (name, rows x n array).");
  py::class_<PvdWriter>(m, "PvdWriter", "A ParaView time series (.pvd and one .vtu per frame).")
      .def(py::init<std::string, std::string>(), "directory"_a, "basename"_a)
      .def("add_frame", &PvdWriter::AddFrame, "time"_a, "mesh"_a, "positions"_a, "point_data"_a = VtkPointData{})
      .def("write", &PvdWriter::Write)
      .def_property_readonly("num_frames", &PvdWriter::num_frames);
}

}  // namespace diffpd::python
