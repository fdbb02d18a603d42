// Row 2, Rolling sphere (timing only): PROBLEMS.md section 2.
#include "diffpd/solvers/core/initial_state_block.h"
#include "paper/activation_variables.h"
#include "paper/paper_meshes.h"
#include "paper/paper_rows.h"
#include "paper/trajectory_losses.h"

namespace diffpd::problems {

PaperRow MakeRollingSphereRow(RowSize size) {
  const bool paper = size == RowSize::kPaper;
  // Paper: 10^3 cells of 1 cm; small: 4^3 cells of 2.5 cm. A cell is kept if
  // its centre is within 0.05 of (0.05, 0.05, 0.05).
  const int cells = paper ? 10 : 4;
  const double dx = 0.1 / cells, radius = 0.05;
  const Vec3 centre = Vec3::Constant(0.05);
  PaperRow row;
  row.name = "rolling-sphere";
  row.title = "Rolling sphere (forward and backward timing)";
  row.table_index = 2;
  row.size = size;
  row.time_step = 5e-3;
  row.steps = paper ? 100 : 5;

  Scene& scene = row.scene;
  scene.mesh =
      VoxelCells([&](int i, int j, int k) { return (dx * Vec3(i + 0.5, j + 0.5, k + 0.5) - centre).norm() < radius; },
                 Eigen::Vector3i::Constant(cells), dx);
  scene.material = MaterialParameters{2e6, 0.4, 1e3};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  FrictionalContact ground;
  ground.surface = ContactSurface::Plane(Vec3::UnitZ(), 0.0);
  ground.nodes = SingleElementNodes(scene.mesh);
  scene.frictional_contacts = {ground};
  const Mesh& mesh = scene.mesh;
  const int n = mesh.num_vertices();

  // Seed 42: g_q, g_v, then the noise of q0; v0 = omega x q0 about the origin.
  NumpyRandom rng(42);
  const VectorXd gq = rng.Normal(3 * n), gv = rng.Normal(3 * n);
  VectorXd q0 = Eigen::Map<const VectorXd>(mesh.vertices.data(), 3 * n) + rng.Normal(3 * n, 0.001);
  VectorXd v0(3 * n);
  const Vec3 omega(0, 10, 0);
  for (int i = 0; i < n; ++i) v0.segment<3>(3 * i) = omega.cross(Vec3(q0.segment<3>(3 * i)));

  row.base.initial = State{VectorXd::Zero(3 * n), VectorXd::Zero(3 * n)};
  row.base.inputs.assign(row.steps, StepInput{});
  row.base.material = scene.material;
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  using solvers::InitialStateBlock;
  auto x0 = std::make_shared<InitialStateBlock>(InitialStateBlock::kPosition, all, InitialStateBlock::kPerNode);
  x0->SetInitial(q0);
  auto v0_block = std::make_shared<InitialStateBlock>(InitialStateBlock::kVelocity, all, InitialStateBlock::kPerNode);
  v0_block->SetInitial(v0);
  row.variables = {x0, v0_block, std::make_shared<ConstantForceVariables>(3 * n)};
  row.loss = {{std::make_shared<LinearFinalStateLoss>(gq, gv), 1.0}};

  row.budget.optimised = false;
  row.solver.rel_tolerance = 1e-4;
  row.solver.max_iterations = 5000;
  row.solver.paper_threads = -1;
  row.paper.newton_pcg = {107.3, 31.3, {}, {}};
  row.paper.newton_cholesky = {135.6, 36.6, {}, {}};
  row.paper.diffpd = {14.0, 5.7, {}, {}};
  row.paper.speedup = 8;
  row.notes = CommonRowNotes();
  row.notes.push_back(FrictionalContactNote());
  row.notes.push_back(
      "rel_tol: the paper does not say which of its swept values (1e-1 ... 1e-7) the Table used; 1e-4 here");
  row.notes.push_back("variables: the gradient is taken w.r.t. x0, v0 and a constant force f (zero at x_init)");
  return row;
}

}  // namespace diffpd::problems
