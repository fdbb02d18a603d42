// Row 8, Quadruped (gait parameters): PROBLEMS.md section 8.
#include <cmath>

#include "diffpd/solvers/core/trajectory_function.h"
#include "paper/activation_variables.h"
#include "paper/paper_meshes.h"
#include "paper/paper_rows.h"

namespace diffpd::problems {

PaperRow MakeQuadrupedRow(RowSize size) {
  const bool paper = size == RowSize::kPaper;
  PaperRow row;
  row.name = "quadruped";
  row.title = "Quadruped (gait parameters)";
  row.table_index = 8;
  row.size = size;
  row.time_step = 0.01;
  // The body starts 25 mm above the ground and lands in its 8th step. Before
  // that the muscles cannot move the mean node (with the original's equal
  // node masses it is the centre of mass), so the small instance runs 10
  // steps: 3 on the ground, and a loss that depends on the gait.
  row.steps = paper ? 100 : 10;

  // 12 x 12 x 9 cells of 1/30 m: the body is z-cells 6-8 over the whole
  // footprint, the legs are 3 x 3 cell columns at the corners below it.
  const double dx = 0.1 / 3;
  auto in_leg = [](int i) { return i <= 2 || i >= 9; };
  Scene& scene = row.scene;
  scene.mesh = VoxelCells([&](int i, int j, int k) { return k >= 6 || (in_leg(i) && in_leg(j)); },
                          Eigen::Vector3i(12, 12, 9), dx);
  scene.material = MaterialParameters{1e6, 0.49, 300};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  const Mesh& mesh = scene.mesh;
  // Contact: the bottom nodes on the perimeter of each foot's 4 x 4 node grid.
  auto on_rim = [](int i) { return i == 0 || i == 3 || i == 9 || i == 12; };
  FrictionalContact ground;
  ground.surface = ContactSurface::Plane(Vec3::UnitZ(), 0.0);
  ground.nodes = NodesWhere(mesh, [&](const Vec3& p) {
    const int i = static_cast<int>(std::lround(p.x() / dx)), j = static_cast<int>(std::lround(p.y() / dx));
    return std::abs(p.z()) < 1e-9 && (on_rim(i) || on_rim(j));
  });
  scene.frictional_contacts = {ground};
  // Muscles: every leg element, fibre z. Leg front if its centre has x >= 0.2,
  // left if y >= 0.2; within a leg the two columns of larger x pull forward
  // ("F"), the other ("B") back. Muscle index 4 front + 2 forward + left.
  scene.muscles.resize(8);
  for (Muscle& m : scene.muscles) {
    m.fibers = {Vec3::UnitZ()};
    m.stiffness = 5e5;
  }
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Eigen::Vector3i cell = ElementCell(mesh, e, dx);
    if (cell.z() >= 6) continue;
    const Vec3 c = ElementCentre(mesh, e);
    const bool front = c.x() >= 0.2, left = c.y() >= 0.2;
    const bool forward = cell.x() % 9 >= 1;  // columns 1, 2 of the rear legs, 10, 11 of the front
    scene.muscles[4 * front + 2 * forward + left].elements.push_back(e);
  }
  std::vector<GaitActivationVariables::GaitMuscle> gait;
  for (int m = 0; m < 8; ++m) gait.push_back({m, m >= 4, (m & 2) != 0});
  const int n = mesh.num_vertices();

  State initial{Eigen::Map<const VectorXd>(mesh.vertices.data(), 3 * n), VectorXd::Zero(3 * n)};
  for (int i = 0; i < n; ++i) initial.x(3 * i + 2) += 0.025;
  row.base.initial = initial;
  row.base.inputs.assign(row.steps, StepInput{VectorXd(), VectorXd::Ones(8)});
  row.base.material = scene.material;
  // The gait's frequency bounds are per step of the paper's 100 frames.
  auto activation = std::make_shared<GaitActivationVariables>(gait, 8, row.steps, 1.0);
  const VectorXd lower = Eigen::Vector3d(0.5, 0.5, 2 * M_PI / 100);
  const VectorXd upper = Eigen::Vector3d(1.0, 1.0, 2 * M_PI / 5);
  SetBlockBounds(activation.get(), lower, upper);
  // Seed 42: x_init = 0.01 (0.5 u + 0.5, 0.5 u + 0.5, U(w bounds)) (below the
  // bounds: L-BFGS-B projects it), then 16 normalisation draws.
  NumpyRandom rng(42);
  const double af = 0.5 * rng.Uniform() + 0.5, ab = 0.5 * rng.Uniform() + 0.5;
  const double w = rng.Uniform(lower(2), upper(2));
  activation->SetInitial(Eigen::Vector3d(af * 0.01, ab * 0.01, w * 0.01));
  row.random_draws = UniformDraws(&rng, lower, upper, 16);
  row.variables = {activation};

  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  row.loss = {{std::make_shared<solvers::PointCoordinate>(solvers::MeanOf(n, all), solvers::kFinalState, Vec3(-1, 0, 0),
                                                          "mean_position_x"),
               1.0}};
  row.baseline = LossBaseline::kDiffPdFinal;

  row.budget.ftol = 1e-3;
  row.budget.max_iterations = 25;
  row.solver.rel_tolerance = 1e-4;
  row.paper.newton_pcg = {289.2, 51.5, 69, -1.8};
  row.paper.newton_cholesky = {246.3, 47.8, 54, -1.1};
  row.paper.diffpd = {50.2, 15.8, 30, 0.0};
  row.paper.speedup = 4;
  row.notes = CommonRowNotes();
  row.notes.push_back(FrictionalContactNote());
  return row;
}

}  // namespace diffpd::problems
