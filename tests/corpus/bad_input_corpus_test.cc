// Bad inputs across the library's entry points, one row each: malformed
// files for every reader, out-of-range scene fields, solver options and step
// inputs, rollouts handed to a simulator of another scene or settings, and
// command-line flags. Every row must be refused with the exact message that
// names the input and the constraint it breaks (nothing crashes, nothing
// continues with NaN).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "calibration/starfish_recording.h"
#include "cli/command_line.h"
#include "control/swimmer_control.h"
#include "diffpd/captured_motion.h"
#include "diffpd/error.h"
#include "diffpd/gmsh_io.h"
#include "diffpd/scene.h"
#include "diffpd/simulator.h"
#include "diffpd/solver_options.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/tetgen_io.h"
#include "test_scenes.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd {
namespace {

using testing::MessageOf;

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

const testing::TemporaryDirectory& Directory() {
  static const testing::TemporaryDirectory directory("diffpd-bad-input-corpus");
  return directory;
}

// Writes `text` to a fresh file of the corpus directory; returns its path.
std::string Write(const std::string& name, const std::string& text) { return Directory().WriteFile(name, text); }

// One bad input: what it is, the call that must refuse it, the message.
struct Row {
  std::string input;
  std::function<void()> call;
  std::string expected;
};

// Runs the rows; returns how many there were.
size_t ExpectRefused(const std::vector<Row>& rows) {
  for (const Row& row : rows) {
    SCOPED_TRACE(row.input);
    EXPECT_EQ(MessageOf<InvalidInputError>(row.call), row.expected);
  }
  return rows.size();
}

// ---- files ------------------------------------------------------------------

std::vector<Row> ObjRows() {
  const auto obj = [](const std::string& name, const std::string& text) {
    const std::string path = Write(name + ".obj", text);
    return std::pair<std::string, std::function<void()>>(path, [path] { ReadObj(path); });
  };
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, const std::string& text, const std::string& message) {
    auto [path, call] = obj(name, text);
    rows.push_back({"OBJ " + name, call, message.empty() ? message : path + message});
  };
  add("short_vertex", "v 1 2\n", ":1: expected x y z coordinates, got 'v 1 2'");
  add("word_coordinate", "v abc 0 0\n", ":1: expected x coordinate (a finite number), got 'abc'");
  add("nan_coordinate", "v 0 nan 0\n", ":1: expected y coordinate (a finite number), got 'nan'");
  add("inf_coordinate", "v 0 0 inf\n", ":1: expected z coordinate (a finite number), got 'inf'");
  add("two_vertex_face", tri + "f 1 2\n", ":4: a face needs at least 3 vertices, got 2");
  add("letter_in_face", tri + "f 1/a 2 3\n", ":4: malformed face entry '1/a'");
  add("zero_index", tri + "f 0 1 2\n", ":4: face index 0 is invalid (OBJ indices start at 1)");
  add("index_past_end", tri + "f 1 2 12\n", ":4: face index 12 out of range (file has 3 vertices)");
  add("negative_index_past_start", tri + "f -1 -2 -12\n",
      ":4: face index -12 out of range (3 vertices read before this line)");
  add("huge_index", tri + "f 1 2 99999999999999999999\n", ":4: malformed face entry '99999999999999999999'");
  add("no_faces", tri, ": no faces");
  add("empty", "", ": no vertices");
  rows.push_back({"OBJ missing file", [] { ReadObj(Directory().File("missing.obj")); },
                  "cannot open '" + Directory().File("missing.obj") + "'"});
  rows.push_back({"OBJ directory", [] { ReadObj(Directory().path().string()); },
                  "cannot open '" + Directory().path().string() + "': it is a directory, not a file"});
  return rows;
}

std::vector<Row> TetGenRows() {
  std::vector<Row> rows;
  const std::string good_node = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
  const std::string good_ele = "1 4 0\n0 0 1 2 3\n";
  const auto add = [&](const std::string& name, const std::string& node, const std::string& ele,
                       const std::string& message) {
    const std::string node_path = Write(name + ".node", node), ele_path = Write(name + ".ele", ele);
    std::string expected = message;
    if (expected.rfind("NODE", 0) == 0) expected = node_path + expected.substr(4);
    if (expected.rfind("ELE", 0) == 0) expected = ele_path + expected.substr(3);
    rows.push_back({"TetGen " + name, [node_path, ele_path] { ReadTetGen(node_path, ele_path); }, expected});
  };
  add("dimension_2", "4 2 0 0\n", good_ele, "NODE:1: expected dimension 3, got 2");
  add("huge_count", "1000000000 3 0 0\n", good_ele,
      "NODE:1: the number of points = 1000000000 is more than the file's 17 bytes can hold");
  add("first_number_5", "4 3 0 0\n5 0 0 0\n", good_ele, "NODE:2: first point number must be 0 or 1, got 5");
  add("out_of_sequence", "4 3 0 0\n0 0 0 0\n1 1 0 0\n7 0 1 0\n3 0 0 1\n", good_ele,
      "NODE:4: point number 7 out of sequence (expected 2)");
  add("truncated_nodes", "4 3 0 0\n0 0 0 0\n1 1 0 0\n", good_ele, "NODE: file ends after 2 of 4 points");
  add("nan_node", "4 3 0 0\n0 0 0 0\n1 nan 0 0\n2 0 1 0\n3 0 0 1\n", good_ele,
      "NODE:3: expected x coordinate (a finite number), got 'nan'");
  add("ten_node_tets", good_node, "1 10 0\n",
      "ELE:1: only 4-node tetrahedra are supported, got 10 nodes per tetrahedron");
  add("node_out_of_range", good_node, "1 4 0\n0 0 1 2 9\n",
      "ELE:2: node 9 out of range (the .node file numbers its 4 points 0..3)");
  add("negative_tet_count", good_node, "-1 4 0\n", "ELE:1: the number of tetrahedra must be >= 0, got -1");
  add("inverted_tet", good_node, "1 4 0\n0 0 2 1 3\n",
      "ELE: element 0 is inverted or degenerate (signed volume -0.166667 m^3)");
  add("truncated_tets", good_node, "2 4 0\n0 0 1 2 3\n", "ELE: file ends after 1 of 2 tetrahedra");
  return rows;
}

// A Gmsh 4.1 file with one tet4 whose $Nodes and $Elements bodies are given.
std::string Msh(const std::string& nodes, const std::string& elements) {
  return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n" + nodes + "$EndNodes\n$Elements\n" + elements +
         "$EndElements\n";
}

std::vector<Row> GmshRows() {
  const std::string nodes = "1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const std::string tet = "1 1 1 1\n3 1 4 1\n1 1 2 3 4\n";
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, const std::string& text, const std::string& message) {
    const std::string path = Write(name + ".msh", text);
    rows.push_back({"Gmsh " + name, [path] { ReadGmsh(path); }, path + message});
  };
  add("not_msh", "foo\n", ":1: not a Gmsh MSH file (expected $MeshFormat, got 'foo')");
  add("version_2", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n",
      ":2: MSH version 2.2 is not supported; only 4.1 (export with 'gmsh -format msh41')");
  add("binary", "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n",
      ":2: binary MSH files are not supported; export ASCII (Gmsh option Mesh.Binary = 0)");
  add("duplicate_tag", Msh("1 4 1 4\n3 1 0 4\n1\n2\n3\n3\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n", tet),
      ":10: node tag 3 appears twice");
  add("unknown_node", Msh(nodes, "1 1 1 1\n3 1 4 1\n1 1 2 3 99\n"),
      ":19: element 1 references node tag 99, which is not in $Nodes");
  add("short_hex", Msh(nodes, "1 1 1 1\n3 1 5 1\n7 1 2 3 4\n"),
      ":19: element 7 has 4 node tags, expected 8 for type 5 (hex8)");
  add("type_11", Msh(nodes, "1 1 1 1\n3 1 11 1\n1 1 2 3 4\n"),
      ":18: 3D element type 11 is not supported (only 4 = tet4 and 5 = hex8)");
  add("no_end_nodes", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n" + nodes, ":14: section $Nodes has no $EndNodes");
  add("no_elements", Msh(nodes, "0 0 0 0\n"), ": no tet4 (type 4) or hex8 (type 5) elements");
  add("huge_block", Msh("1 3000000000 1 3000000000\n3 1 0 3000000000\n", tet),
      ":6: numNodesInBlock = 3000000000 is more than the file's 144 bytes can hold");
  add("nan_coordinate", Msh("1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\nnan 0 0\n0 1 0\n0 0 1\n", tet),
      ":12: expected x coordinate (a finite number), got 'nan'");
  add("negative_tag", Msh("1 4 1 4\n3 1 0 4\n1\n2\n-3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n", tet),
      ":9: node tag -3 is invalid: must be >= 1");
  add("inverted", Msh(nodes, "1 1 1 1\n3 1 4 1\n1 1 3 2 4\n"),
      ": element 0 is inverted or degenerate (signed volume -0.166667 m^3)");
  return rows;
}

std::vector<Row> CapturedMotionRows() {
  const std::string header = "marker,0,vertex,0\nmarker,1,vertex,1\ntime,marker,x,y,z\n";
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, const std::string& text, const std::string& message) {
    const std::string path = Write(name + ".csv", text);
    rows.push_back({"captured motion " + name, [path] { ReadCapturedMotion(path); }, path + message});
  };
  add("short_marker", "marker,1,vertex\n",
      ":1: expected 'marker,<id>,vertex,<v>' or 'marker,<id>,element,<e>,<c0>,<c1>,<c2>', got 'marker,1,vertex'");
  add("marker_twice", "marker,1,vertex,0\nmarker,1,vertex,2\ntime,marker,x,y,z\n0,1,0,0,0\n",
      ":2: marker id 1 is declared twice (first on line 1)");
  add("marker_after_header", header + "marker,2,vertex,2\n", ":4: marker declarations must come before the header");
  add("bad_header", "marker,0,vertex,0\n0,1,2,3,4\n",
      ":2: expected the header 'time,marker,x,y,z' or 'time,marker,x,y,z,wx,wy,wz', got '0,1,2,3,4'");
  add("four_fields", header + "0,0,1,2\n", ":4: expected 5 fields (time,marker,x,y,z), got 4");
  add("word_x", header + "0,0,abc,0,0\n", ":4: x is not a number: 'abc'");
  add("fractional_marker", header + "0,1.5,0,0,0\n", ":4: marker is not an integer: '1.5'");
  add("inf_y", header + "0,0,0,inf,0\n", ":4: y = inf is not finite");
  add("far_x", header + "0,0,1e300,0,0\n", ":4: x = 1e+300 is invalid: must be within +-1000000 (m)");
  add("negative_time", header + "-0.1,0,0,0,0\n", ":4: time = -0.1 is invalid: must be >= 0 (s)");
  add("negative_weight", "marker,0,vertex,0\ntime,marker,x,y,z,wx,wy,wz\n0,0,0,0,0,1,1,-1\n",
      ":3: wz = -1 is invalid: weights must be >= 0");
  add("huge_weight", "marker,0,vertex,0\ntime,marker,x,y,z,wx,wy,wz\n0,0,0,0,0,1e300,1,1\n",
      ":3: wx = 1e+300 is invalid: weights must be <= 1000000000000 (1/m)");
  add("unknown_marker", header + "0,9,0,0,0\n", ":4: unknown marker id 9 (declared ids: 0, 1)");
  add("time_backwards", header + "0.2,0,0,0,0\n0.1,0,0,0,0\n",
      ":5: time 0.1 of marker 0 is not after its previous sample at time 0.2 (line 4): times must increase strictly "
      "per marker");
  add("no_marker", "time,marker,x,y,z\n", ": no marker declared");
  add("no_samples", header, ": no samples");
  add("negative_marker_id", "marker,-1,vertex,0\n", ":1: marker id -1 is invalid: must be an integer >= 0");
  add("nan_time", header + "nan,0,0,0,0\n", ":4: time = nan is not finite");
  return rows;
}

std::vector<Row> StarfishRecordingRows() {
  const std::string header = "t,tendon,m1x,m1y,m2x,m2y,m3x,m3y,m4x,m4y\n";
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, const std::string& text, const std::string& message) {
    const std::string path = Write("starfish_" + name + ".csv", text);
    rows.push_back({"starfish recording " + name, [path] { problems::ReadStarfishRecording(path); }, path + message});
  };
  add("empty", "", ": empty file (expected a header row and data rows)");
  add("short_header", "a,b,c\n", ":1: expected a header row of 10 column labels, got 3 fields");
  add("nine_fields", header + "0,0,1,2,3,4,5,6,7\n",
      ":2: expected 10 fields (time ms, tendon mm, M1 x, M1 y, ..., M4 x, M4 y), got 9");
  add("word_marker", header + "0,0,1,2,3,abc,5,6,7,8\n", ":2: M2 y is not a number: 'abc'");
  add("nan_marker", header + "0,0,1,2,3,nan,5,6,7,8\n",
      ":2: M2 y = nan is invalid: marker coordinates must be finite and within +-1e+09 (mm)");
  add("inf_time", header + "inf,0,1,2,3,4,5,6,7,8\n", ":2: time = inf is invalid: must be finite (ms)");
  add("inf_tendon", header + "0,inf,1,2,3,4,5,6,7,8\n", ":2: tendon = inf is invalid: must be finite or NaN (mm)");
  add("time_backwards", header + "16.6667,0,1,2,3,4,5,6,7,8\n10,0,1,2,3,4,5,6,7,8\n",
      ":3: time 10 ms is not after the previous row's 16.6667 ms (line 2)");
  add("no_rows", header, ": no data rows");
  add("far_marker", header + "0,0,1e10,2,3,4,5,6,7,8\n",
      ":2: M1 x = 1e+10 is invalid: marker coordinates must be finite and within +-1e+09 (mm)");
  return rows;
}

std::vector<Row> ReferenceCurveRows() {
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, const std::string& text, const std::string& message) {
    const std::string path = Write("curve_" + name + ".csv", text);
    rows.push_back({"reference curve " + name, [path] { problems::ReadReferenceCurve(path, "c"); }, path + message});
  };
  add("header", "x,y\n1,2\n", ":1: expected two finite numbers 'x,y', got 'x,y'");
  add("no_rows", "\n \n", ": no data rows");
  add("one_field", "0,1\n1\n", ":2: expected two finite numbers 'x,y', got '1'");
  add("three_fields", "0,1,2\n", ":1: expected two finite numbers 'x,y', got '0,1,2'");
  add("word", "0,1\n\n1,abc\n", ":3: expected two finite numbers 'x,y', got '1,abc'");
  add("nan", "1,nan\n", ":1: expected two finite numbers 'x,y', got '1,nan'");
  return rows;
}

// ---- scene fields, options, step inputs, rollouts ------------------------------

std::vector<Row> SceneRows() {
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, const std::function<void(Scene*)>& change, const std::string& message) {
    rows.push_back({"scene " + name,
                    [change] {
                      Scene scene = testing::SmallBeamScene();
                      change(&scene);
                      Simulator simulator(scene, testing::TightOptions(Method::kPd));
                    },
                    message});
  };
  add(
      "E = 0", [](Scene* s) { s->material.youngs_modulus = 0; },
      "youngs_modulus = 0 is invalid: must be finite and > 0 (Pa)");
  add(
      "E = nan", [](Scene* s) { s->material.youngs_modulus = kNaN; },
      "youngs_modulus = nan is invalid: must be finite and > 0 (Pa)");
  add(
      "nu = 0.5", [](Scene* s) { s->material.poissons_ratio = 0.5; },
      "poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");
  add(
      "nu = -1", [](Scene* s) { s->material.poissons_ratio = -1; },
      "poissons_ratio = -1 is invalid: must be finite and in (-1, 0.5)");
  add(
      "density = -1", [](Scene* s) { s->material.density = -1; },
      "density = -1 is invalid: must be finite and > 0 (kg/m^3)");
  add(
      "density = inf", [](Scene* s) { s->material.density = kInf; },
      "density = inf is invalid: must be finite and > 0 (kg/m^3)");
  add(
      "gravity nan", [](Scene* s) { s->gravity = Vec3(0, 0, kNaN); }, "scene: gravity has a non-finite component");
  add(
      "no energy", [](Scene* s) { s->energies.clear(); }, "scene: no elastic energy declared (energies is empty)");
  add(
      "dirichlet out of range",
      [](Scene* s) {
        s->dirichlet.dofs.back() = 100000;
        s->dirichlet.values(s->dirichlet.values.size() - 1) = 0;
      },
      "scene: Dirichlet DoF 100000 is out of range [0, 135)");
  add(
      "dirichlet not increasing", [](Scene* s) { std::swap(s->dirichlet.dofs[0], s->dirichlet.dofs[1]); },
      "scene: Dirichlet DoFs must be strictly increasing (1 then 0)");
  add(
      "dirichlet size mismatch", [](Scene* s) { s->dirichlet.values.conservativeResize(1); },
      "scene: dirichlet.dofs has 27 entries but dirichlet.values has 1");
  add(
      "dirichlet nan", [](Scene* s) { s->dirichlet.values(0) = kNaN; },
      "scene: the Dirichlet value of DoF 0 is not finite");
  add(
      "empty region",
      [](Scene* s) {
        s->material_regions.push_back({{}, s->material});
      },
      "scene: material region 0 has no element");
  add(
      "region out of range",
      [](Scene* s) {
        s->material_regions.push_back({{40}, s->material});
      },
      "scene: material region 0 lists element 40, out of range [0, 16)");
  add(
      "region twice",
      [](Scene* s) {
        s->material_regions.push_back({{5, 5}, s->material});
      },
      "scene: material region 0 lists element 5 twice");
  add(
      "regions share",
      [](Scene* s) {
        s->material_regions.push_back({{5}, s->material});
        s->material_regions.push_back({{5}, s->material});
      },
      "scene: element 5 is in material regions 0 and 1");
  add(
      "region E = 0",
      [](Scene* s) {
        MaterialParameters m = s->material;
        m.youngs_modulus = 0;
        s->material_regions.push_back({{1}, m});
      },
      "scene: material region 0: youngs_modulus = 0 is invalid: must be finite and > 0 (Pa)");
  add(
      "damping negative", [](Scene* s) { s->linear_damping = -1; },
      "scene: linear_damping = -1 is invalid: must be finite and >= 0 (1/s)");
  add(
      "damping nan", [](Scene* s) { s->linear_damping = kNaN; },
      "scene: linear_damping = nan is invalid: must be finite and >= 0 (1/s)");
  add(
      "vertex nan", [](Scene* s) { s->mesh.vertices(0, 3) = kNaN; }, "mesh: vertex 3 has a non-finite coordinate");
  add(
      "element node out of range", [](Scene* s) { s->mesh.elements(0, 0) = 1000; },
      "mesh: element 0 references vertex 1000, but the mesh has 45 vertices");
  rows.push_back({"FixNodes node 99",
                  [] {
                    Scene scene = testing::SmallBeamScene();
                    FixNodes(&scene, {99});
                  },
                  "FixNodes: node 99 is out of range [0, 45)"});
  rows.push_back({"FixNodeAxes axis 5",
                  [] {
                    Scene scene = testing::SmallBeamScene();
                    FixNodeAxes(&scene, {1}, {5});
                  },
                  "FixNodeAxes: axis 5 is invalid: must be 0 (x), 1 (y) or 2 (z)"});
  rows.push_back({"FixNodeAxes node -1",
                  [] {
                    Scene scene = testing::SmallBeamScene();
                    FixNodeAxes(&scene, {-1}, {0});
                  },
                  "FixNodeAxes: node -1 is out of range [0, 45)"});
  return rows;
}

std::vector<Row> SolverOptionsRows() {
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, const std::function<void(SolverOptions*)>& change,
                       const std::string& message) {
    rows.push_back({"solver options " + name,
                    [change] {
                      SolverOptions options;
                      change(&options);
                      options.Validate();
                    },
                    message});
  };
  add(
      "time_step = -1", [](SolverOptions* o) { o->time_step = -1; },
      "solver options: time_step = -1 is invalid: must be finite and > 0 (s)");
  add(
      "time_step = nan", [](SolverOptions* o) { o->time_step = kNaN; },
      "solver options: time_step = nan is invalid: must be finite and > 0 (s)");
  add(
      "time_step = inf", [](SolverOptions* o) { o->time_step = kInf; },
      "solver options: time_step = inf is invalid: must be finite and > 0 (s)");
  add(
      "abs_tolerance = -1", [](SolverOptions* o) { o->abs_tolerance = -1; },
      "solver options: abs_tolerance = -1 is invalid: must be finite and >= 0");
  add(
      "rel_tolerance = 2", [](SolverOptions* o) { o->rel_tolerance = 2; },
      "solver options: rel_tolerance = 2 is invalid: must be in [0, 1)");
  add(
      "rel_tolerance = nan", [](SolverOptions* o) { o->rel_tolerance = kNaN; },
      "solver options: rel_tolerance = nan is invalid: must be in [0, 1)");
  add(
      "max_iterations = 0", [](SolverOptions* o) { o->max_iterations = 0; },
      "solver options: max_iterations = 0 is invalid: must be >= 1");
  add(
      "armijo_c = 1", [](SolverOptions* o) { o->armijo_c = 1; },
      "solver options: armijo_c = 1 is invalid: must be in (0, 1)");
  add(
      "max_line_search_steps = -1", [](SolverOptions* o) { o->max_line_search_steps = -1; },
      "solver options: max_line_search_steps = -1 is invalid: must be >= 1");
  add(
      "pcg_rel_tolerance = 0", [](SolverOptions* o) { o->pcg_rel_tolerance = 0; },
      "solver options: pcg_rel_tolerance = 0 is invalid: must be in (0, 1)");
  add(
      "pcg_max_iterations = 0", [](SolverOptions* o) { o->pcg_max_iterations = 0; },
      "solver options: pcg_max_iterations = 0 is invalid: must be >= 1");
  add(
      "lbfgs_history = -1", [](SolverOptions* o) { o->lbfgs_history = -1; },
      "solver options: lbfgs_history = -1 is invalid: must be >= 1");
  add(
      "lbfgs_weight_scale = 0", [](SolverOptions* o) { o->lbfgs_weight_scale = 0; },
      "solver options: lbfgs_weight_scale = 0 is invalid: must be in (0, 1]");
  add(
      "backward_rel_tolerance = -1", [](SolverOptions* o) { o->backward_rel_tolerance = -1; },
      "solver options: backward_rel_tolerance = -1 is invalid: must be in [0, 1) (0: derived from the forward's "
      "accuracy)");
  add(
      "backward_tolerance_factor = nan", [](SolverOptions* o) { o->backward_tolerance_factor = kNaN; },
      "solver options: backward_tolerance_factor = nan is invalid: must be in (0, 1]");
  add(
      "backward_max_iterations = 0", [](SolverOptions* o) { o->backward_max_iterations = 0; },
      "solver options: backward_max_iterations = 0 is invalid: must be >= 1");
  add(
      "adjoint_guess_solutions = -1", [](SolverOptions* o) { o->adjoint_guess_solutions = -1; },
      "solver options: adjoint_guess_solutions = -1 is invalid: must be >= 0");
  add(
      "max_extent_ratio = 0.5", [](SolverOptions* o) { o->max_extent_ratio = 0.5; },
      "solver options: max_extent_ratio = 0.5 is invalid: must be > 1 (infinity: no bound)");
  add(
      "method = 99", [](SolverOptions* o) { o->method = static_cast<Method>(99); },
      "solver options: method = 99 is invalid: must be a Method: semi-implicit (0), newton-cholesky (1), newton-pcg "
      "(2), pd (3), pd-lbfgs (4) or newton-ldlt (5)");
  add(
      "num_threads = -1", [](SolverOptions* o) { o->num_threads = -1; },
      "solver options: num_threads = -1 is invalid: must be in [0, " + std::to_string(MaxSolverThreads()) +
          "] (0: OpenMP default; at most 4 x the " + std::to_string(MaxSolverThreads() / 4) + " processors)");
  return rows;
}

std::vector<Row> StepRows() {
  std::vector<Row> rows;
  // Each call builds its simulator: rows are independent.
  const auto add = [&](const std::string& name, const std::function<void(State*, StepInput*)>& change,
                       const std::string& message) {
    rows.push_back({"step " + name,
                    [change] {
                      Simulator sim(testing::SmallBeamScene(), testing::TightOptions(Method::kPd));
                      State state = sim.RestState();
                      StepInput input;
                      change(&state, &input);
                      sim.Step(state, input);
                    },
                    message});
  };
  add(
      "x too short", [](State* s, StepInput*) { s->x.conservativeResize(3); },
      "state.x has 3 entries, expected 135 (3 x number of nodes)");
  add(
      "v too long",
      [](State* s, StepInput*) {
        s->v.conservativeResize(s->v.size() + 3);
        s->v.tail(3).setZero();
      },
      "state.v has 138 entries, expected 135 (3 x number of nodes)");
  add(
      "x nan", [](State* s, StepInput*) { s->x(7) = kNaN; }, "state.x has a non-finite entry");
  add(
      "v inf", [](State* s, StepInput*) { s->v(2) = kInf; }, "state.v has a non-finite entry");
  add(
      "force wrong size", [](State* s, StepInput* in) { in->external_force = VectorXd::Zero(5); },
      "external_force has 5 entries, expected 135 (3 x number of nodes)");
  add(
      "force nan",
      [](State* s, StepInput* in) {
        in->external_force = VectorXd::Zero(s->x.size());
        in->external_force(4) = kNaN;
      },
      "external_force has a non-finite entry");
  add(
      "activation without muscles", [](State*, StepInput* in) { in->activation = VectorXd::Ones(2); },
      "activation has 2 entries, expected 0 (one per muscle)");
  add(
      "held quad faces without quad hydrodynamics",
      [](State*, StepInput* in) {
        in->wetted_quads = {1, 0};
      },
      "wetted_quads has 2 entries, expected 0 (one per quad_hydrodynamics face)");
  rows.push_back({"simulate with a held quad face that is neither wet nor dry",
                  [] {
                    Scene scene = testing::SmallBeamScene();
                    scene.quad_hydrodynamics = QuadHydrodynamics();
                    scene.quad_hydrodynamics->quads = BoundaryQuads(scene.mesh);
                    Simulator sim(scene, testing::TightOptions(Method::kPd));
                    std::vector<StepInput> inputs(3);
                    inputs[1].wetted_quads.assign(scene.quad_hydrodynamics->quads.cols(), 1);
                    inputs[1].wetted_quads[4] = 7;
                    sim.Simulate(sim.RestState(), inputs);
                  },
                  "Simulate: inputs[1]: wetted_quads[4] = 7 is invalid: must be 0 or 1"});
  rows.push_back({"simulate with a short external force",
                  [] {
                    Simulator sim(testing::SmallBeamScene(), testing::TightOptions(Method::kPd));
                    sim.Simulate(sim.RestState(), std::vector<StepInput>(1, StepInput{VectorXd::Zero(2), {}}));
                  },
                  "Simulate: inputs[0]: external_force has 2 entries, expected 135 (3 x number of nodes)"});
  rows.push_back({"simulate with an activation at its third step on a scene without muscles",
                  [] {
                    Simulator sim(testing::SmallBeamScene(), testing::TightOptions(Method::kPd));
                    std::vector<StepInput> inputs(4);
                    inputs[2].activation = VectorXd::Constant(1, kNaN);
                    sim.Simulate(sim.RestState(), inputs);
                  },
                  "Simulate: inputs[2]: activation has 1 entries, expected 0 (one per muscle)"});
  return rows;
}

// A 2-step rollout of the small beam, and a loss gradient for it.
Rollout BeamRollout(const SolverOptions& options, bool tets = false) {
  Simulator sim(testing::SmallBeamScene(tets), options);
  return sim.Simulate(sim.RestState(), std::vector<StepInput>(2));
}

LossGradient OnesLoss(const Rollout& rollout) {
  LossGradient loss(static_cast<int>(rollout.inputs.size()));
  for (auto& d : loss.dx) d = VectorXd::Ones(rollout.states[0].x.size());
  for (auto& d : loss.dv) d = VectorXd::Zero(rollout.states[0].x.size());
  return loss;
}

std::vector<Row> RolloutRows() {
  std::vector<Row> rows;
  const SolverOptions pd = testing::TightOptions(Method::kPd);
  const auto backward = [pd](const Rollout& rollout, const LossGradient& loss, const SolverOptions& options) {
    Simulator sim(testing::SmallBeamScene(), options);
    sim.Backward(rollout, loss);
  };
  rows.push_back({"rollout of a tet mesh to a hex simulator",
                  [=] {
                    const Rollout r = BeamRollout(pd, true);
                    backward(r, OnesLoss(r), pd);
                  },
                  "Backward: the rollout's state 0 has x with 108 entries, expected 135 (3 x number of nodes)"});
  rows.push_back(
      {"rollout of another time step",
       [=] {
         const Rollout r = BeamRollout(pd);
         SolverOptions other = pd;
         other.time_step = 0.02;
         backward(r, OnesLoss(r), other);
       },
       "Backward: the rollout was made with another time step (0.01 s) than the simulator's current one (0.02 "
       "s)"});
  rows.push_back({"rollout of another method",
                  [=] {
                    const Rollout r = BeamRollout(pd);
                    backward(r, OnesLoss(r), testing::TightOptions(Method::kNewtonCholesky));
                  },
                  "Backward: the rollout was made with another method (pd) than the simulator's current one "
                  "(newton-cholesky)"});
  rows.push_back({"rollout of another material",
                  [=] {
                    const Rollout r = BeamRollout(pd);
                    Simulator sim(testing::SmallBeamScene(), pd);
                    MaterialParameters m = sim.scene().material;
                    m.youngs_modulus *= 2;
                    sim.SetMaterial(m);
                    sim.Backward(r, OnesLoss(r));
                  },
                  "Backward: the rollout was made with another material (E = 200000 Pa, nu = 0.4, rho = 1000 kg/m^3) "
                  "than the simulator's current one (E = 400000 Pa, nu = 0.4, rho = 1000 kg/m^3)"});
  rows.push_back({"rollout without inputs",
                  [=] {
                    Rollout r = BeamRollout(pd);
                    const LossGradient loss = OnesLoss(r);
                    r.inputs.pop_back();
                    backward(r, loss, pd);
                  },
                  "Backward: the rollout has 3 states for 1 inputs (needs one more state than inputs)"});
  rows.push_back({"rollout holding quad faces to a simulator without quad hydrodynamics",
                  [=] {
                    Rollout r = BeamRollout(pd);
                    r.inputs[1].wetted_quads = {0, 1, 1};
                    backward(r, OnesLoss(r), pd);
                  },
                  "Backward: the rollout's input 1: wetted_quads has 3 entries, expected 0 (one per "
                  "quad_hydrodynamics face)"});
  rows.push_back({"loss gradient nan",
                  [=] {
                    const Rollout r = BeamRollout(pd);
                    LossGradient loss = OnesLoss(r);
                    loss.dx[1](3) = kNaN;
                    backward(r, loss, pd);
                  },
                  "loss.dx has a non-finite entry"});
  rows.push_back({"loss gradient wrong size",
                  [=] {
                    const Rollout r = BeamRollout(pd);
                    LossGradient loss = OnesLoss(r);
                    loss.dv[2] = VectorXd::Zero(4);
                    backward(r, loss, pd);
                  },
                  "loss.dv has 4 entries, expected 135 (3 x number of nodes)"});
  return rows;
}

// ---- command line ---------------------------------------------------------------

std::vector<Row> CommandLineRows() {
  // The command line reports on stderr and returns 2; the row's call turns
  // that into an InvalidInputError carrying the reported message.
  std::vector<Row> rows;
  const auto add = [&](const std::vector<std::string>& args, const std::string& message) {
    std::string line = "diffpd";
    for (const std::string& a : args) line += " " + a;
    rows.push_back({line,
                    [args] {
                      std::vector<std::string> argv = {"diffpd"};
                      argv.insert(argv.end(), args.begin(), args.end());
                      ::testing::internal::CaptureStderr();
                      ::testing::internal::CaptureStdout();
                      const int status = problems::RunCommandLine(argv);
                      ::testing::internal::GetCapturedStdout();
                      std::string error = ::testing::internal::GetCapturedStderr();
                      const std::string prefix = "diffpd: invalid input: ";
                      if (status != 2 || error.rfind(prefix, 0) != 0)
                        throw std::runtime_error("status " + std::to_string(status) + ": " + error);
                      error = error.substr(prefix.size());
                      if (!error.empty() && error.back() == '\n') error.pop_back();
                      throw InvalidInputError(error);
                    },
                    message});
  };
  add({"run", "cantilever", "--steps", "1e9x"}, "--steps = 1e9x is invalid: must be an integer >= 1");
  add({"run", "cantilever", "--dt", "1e400"}, "--dt = 1e400 is invalid: must be finite and > 0 (s)");
  add({"run", "cantilever", "--rtol", "1"}, "--rtol = 1 is invalid: must be in (0, 1)");
  add({"run", "cantilever", "--lbfgs-scale", "0"}, "--lbfgs-scale = 0 is invalid: must be in (0, 1]");
  add({"run", "cantilever", "--lbfgs-scale", "nan"}, "--lbfgs-scale = nan is invalid: must be in (0, 1]");
  add({"run", "cantilever", "--verbosity", "-3"}, "--verbosity = -3 is invalid: must be an integer in [0, 2]");
  add({"run", "cantilever", "--method", "nosuch"},
      "unknown method 'nosuch': valid methods are semi-implicit, newton-cholesky, newton-pcg, pd, pd-lbfgs, "
      "newton-ldlt");
  add({"bench", "cantilever", "--repeat", "-2"}, "--repeat = -2 is invalid: must be an integer >= 1");
  add({"bench", "cantilever", "--scales", "3"},
      "--scales is not used without --scaling (the element-count factors of --scaling)");
  add({"bench", "cantilever", "--scaling", "--scales", "3"},
      "scale = 3 is invalid: must be a power of 2 (1, 2, 4, 8, ...)");
  add({"bench", "cantilever", "--max-iterations", "0"}, "--max-iterations = 0 is invalid: must be an integer >= 1");
  add({"stress", "--E", "-1"}, "--E = -1 is invalid: must be finite and > 0 (Pa)");
  add({"stress", "--nu", "0.5"}, "--nu = 0.5 is invalid: must be finite and in (-1, 0.5)");
  add({"stress", "--dt", "0"}, "--dt = 0 is invalid: must be finite and > 0 (s)");
  add({"stress", "--abs-tol", "-1"}, "--abs-tol = -1 is invalid: must be finite and > 0 (N)");
  add({"gradcheck", "cantilever", "--tol", "-1"}, "--tol = -1 is invalid: must be finite and > 0");
  add({"gradcheck", "cantilever", "--directions", "0"}, "--directions = 0 is invalid: must be an integer >= 1");
  add({"run", "calibrate-starfish", "--seconds", "-1"}, "--seconds = -1 is invalid: must be finite and > 0 (s)");
  add({"run", "calibrate-starfish", "--calibrate", Directory().File("missing.csv")},
      "cannot open '" + Directory().File("missing.csv") + "'");
  const std::string not_json = Write("table_not_json.json", "{\"date\": ");
  add({"table", "--resume", "--json", not_json},
      "--resume: '" + not_json +
          "' is not JSON: [json.exception.parse_error.101] parse error at line 1, column 10: syntax error while "
          "parsing value - unexpected end of input; expected '[', '{', or a literal");
  const std::string no_date = Write("table_no_date.json", "{}");
  add({"table", "--resume", "--json", no_date}, "table JSON: the document has no field 'date'");
  const std::string missing = Directory().File("missing_table.json");
  add({"table", "--resume", "--json", missing}, "--resume: cannot open '" + missing + "'");
  return rows;
}

TEST(BadInputCorpusTest, EveryRowIsRefusedWithTheMessageNamingTheInputAndItsConstraint) {
  size_t count = 0;
  count += ExpectRefused(ObjRows());
  count += ExpectRefused(TetGenRows());
  count += ExpectRefused(GmshRows());
  count += ExpectRefused(CapturedMotionRows());
  count += ExpectRefused(StarfishRecordingRows());
  count += ExpectRefused(ReferenceCurveRows());
  count += ExpectRefused(SceneRows());
  count += ExpectRefused(SolverOptionsRows());
  count += ExpectRefused(StepRows());
  count += ExpectRefused(RolloutRows());
  count += ExpectRefused(CommandLineRows());
  EXPECT_GE(count, 100u);
}

}  // namespace
}  // namespace diffpd
