#include "control/starfish_control.h"

#include <array>
#include <cmath>
#include <map>

#include "diffpd/error.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/voxelizer.h"

namespace diffpd::problems {
namespace {

constexpr int kCells = 22;  // voxels per side
constexpr double kDx = 0.1;

bool Occupied(int i, int j) { return (i >= 10 && i < 12) || (j >= 10 && j < 12); }

// Grid indices of cells and nodes of the voxel grid.
struct Grid {
  Mesh mesh;
  std::map<std::array<int, 3>, int> node;  // (i, j, k) -> vertex
  std::map<std::array<int, 3>, int> cell;  // (i, j, k) -> element
  int Node(int i, int j, int k) const { return node.at({i, j, k}); }
  int Cell(int i, int j, int k) const { return cell.at({i, j, k}); }
};

Grid StarfishGrid() {
  Grid g;
  const auto sdf = [](const Vec3& c) {
    const int i = static_cast<int>(std::floor(c.x() / kDx)), j = static_cast<int>(std::floor(c.y() / kDx));
    return Occupied(i, j) ? -1.0 : 1.0;
  };
  g.mesh = VoxelizeSdf(sdf, Vec3::Zero(), Eigen::Vector3i(kCells, kCells, 2), kDx);
  auto index = [](const Vec3& p) {
    return std::array<int, 3>{static_cast<int>(std::lround(p.x() / kDx)), static_cast<int>(std::lround(p.y() / kDx)),
                              static_cast<int>(std::lround(p.z() / kDx))};
  };
  for (int v = 0; v < g.mesh.num_vertices(); ++v) g.node[index(g.mesh.vertices.col(v))] = v;
  for (int e = 0; e < g.mesh.num_elements(); ++e) g.cell[index(g.mesh.vertices.col(g.mesh.elements(0, e)))] = e;
  // Node (11, 11, 1) at the origin.
  const Vec3 centre = g.mesh.vertices.col(g.Node(11, 11, 1));
  g.mesh.vertices.colwise() -= centre;
  return g;
}

}  // namespace

std::string StarfishControl::description() const {
  return "closed-loop swimming: the original starfish (1161 DoFs, 160 delay-line muscles in water) trained through "
         "the simulation with a 243-64-64-4 network (Adam)";
}

Swimmer StarfishControl::MakeSwimmer(bool small) const {
  const Grid g = StarfishGrid();
  Swimmer s;
  s.scene.mesh = g.mesh;
  s.scene.material = MaterialParameters{1e6, 0.45, 1e3};
  s.scene.energies = {ElasticEnergy::kPdCorotated};
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(s.scene.mesh);
  s.scene.quad_hydrodynamics = water;

  // The pairs P0..P7: (arm axis, direction, side-line cell).
  struct Pair {
    int axis;       // 0: the arm runs along x, 1: along y
    bool negative;  // the -x / -y arm (cells 9 -> 0), else +x / +y (12 -> 21)
    int side;       // the side line's cell index on the other axis
  };
  const Pair pairs[8] = {{1, true, 10},  {0, true, 10},  {1, true, 11},  {0, true, 11},
                         {1, false, 10}, {0, false, 10}, {1, false, 11}, {0, false, 11}};
  std::vector<MuscleStrip> strips;
  for (const Pair& p : pairs)
    for (int layer = 0; layer < 2; ++layer) {
      MuscleStrip strip;
      strip.fiber = p.axis == 0 ? Vec3::UnitX() : Vec3::UnitY();
      strip.stiffness = 1e5;
      for (int t = 0; t < 10; ++t) {
        const int along = p.negative ? 9 - t : 12 + t;
        strip.elements.push_back(p.axis == 0 ? g.Cell(along, p.side, layer) : g.Cell(p.side, along, layer));
      }
      strips.push_back(strip);
    }
  s.strips = AddMuscleStrips(&s.scene, strips);
  // Channel c drives pairs 2c and 2c + 1; layer 0 contracts on -w, layer 1 on +w.
  for (int pair = 0; pair < 8; ++pair)
    for (int layer = 0; layer < 2; ++layer) s.drives.push_back(StripDrive{pair / 2, layer == 0 ? -1 : 1});
  s.channels = 4;

  s.observation.reference_node = g.Node(11, 11, 1);
  for (int t = 0; t <= 9; ++t) s.observation.nodes.push_back(g.Node(11, t, 1));
  for (int t = 13; t <= 22; ++t) s.observation.nodes.push_back(g.Node(11, t, 1));
  for (int t = 0; t <= 9; ++t) s.observation.nodes.push_back(g.Node(t, 11, 1));
  for (int t = 13; t <= 22; ++t) s.observation.nodes.push_back(g.Node(t, 11, 1));
  s.hidden_widths = {64, 64};

  s.loss.nodes = {s.observation.reference_node};
  s.loss.direction = Vec3::UnitZ();
  s.loss.side_weight = 1.0;
  s.steps = small ? 40 : 200;
  s.time_step = 3.33e-2;  // the original script's value for 1/30 s
  return s;
}

}  // namespace diffpd::problems
