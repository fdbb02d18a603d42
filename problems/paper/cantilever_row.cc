// Row 1, Cantilever (timing only): PROBLEMS.md section 1.
#include <cmath>

#include "diffpd/box_mesh.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "paper/activation_variables.h"
#include "paper/paper_meshes.h"
#include "paper/paper_rows.h"
#include "paper/trajectory_losses.h"

namespace diffpd::problems {

PaperRow MakeCantileverRow(RowSize size) {
  const bool paper = size == RowSize::kPaper;
  // Paper: 32 x 8 x 8 cells of 1 cm; small: 8 x 2 x 2 cells of 4 cm.
  const int nx = paper ? 32 : 8, ny = paper ? 8 : 2, nz = paper ? 8 : 2;
  const double length = 0.32, width = 0.08;
  PaperRow row;
  row.name = "cantilever";
  row.title = "Cantilever (forward and backward timing)";
  row.table_index = 1;
  row.size = size;
  row.time_step = 0.01;
  row.steps = paper ? 25 : 4;

  Scene& scene = row.scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(nx, ny, nz), Vec3(length, width, width));
  scene.material = MaterialParameters{1e6, 0.45, 1e3};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  const Mesh& mesh = scene.mesh;
  FixNodes(&scene, NodesWhere(mesh, [](const Vec3& p) { return p.x() <= 1e-9; }));
  // Collision energy on the two tip nodes (x = L, z = 0), half-space z >= -0.1.
  PenaltyContact floor;
  floor.normal = Vec3(0, 0, 1);
  floor.offset = -0.1;
  floor.stiffness = 100;
  floor.nodes = NodesWhere(mesh, [&](const Vec3& p) {
    return std::abs(p.x() - length) < 1e-9 && std::abs(p.z()) < 1e-9 &&
           (std::abs(p.y()) < 1e-9 || std::abs(p.y() - width) < 1e-9);
  });
  scene.penalty_contacts = {floor};
  // One muscle per bottom-edge element (j = k = 0: element i ny nz), fibre x.
  std::vector<int> muscles;
  for (int i = 0; i < nx; ++i) {
    Muscle m;
    m.elements = {i * ny * nz};
    m.fibers = {Vec3::UnitX()};
    m.stiffness = 1e5;
    scene.muscles.push_back(m);
    muscles.push_back(i);
  }

  // Twisted beam: the cross-section at x turns about the axis through
  // (x, 0.04, 0.04) by (pi / 2) x / L.
  const int n = mesh.num_vertices();
  VectorXd q0(3 * n);
  for (int i = 0; i < n; ++i) {
    const Vec3 p = mesh.vertices.col(i);
    const double angle = (M_PI / 2) * p.x() / length;
    const double y = p.y() - width / 2, z = p.z() - width / 2;
    q0.segment<3>(3 * i) = Vec3(p.x(), width / 2 + std::cos(angle) * y - std::sin(angle) * z,
                                width / 2 + std::sin(angle) * y + std::cos(angle) * z);
  }

  // Seed 42: the environment's unused force, g_q, g_v, a, f.
  NumpyRandom rng(42);
  rng.Normal(3 * n);
  const VectorXd gq = rng.Normal(3 * n), gv = rng.Normal(3 * n);
  VectorXd a(nx);
  for (int i = 0; i < nx; ++i) a(i) = rng.Uniform();
  const VectorXd f = rng.Normal(3 * n, 0.1) * 1e-3;

  row.base.initial = State{VectorXd::Zero(3 * n), VectorXd::Zero(3 * n)};
  row.base.inputs.assign(row.steps, StepInput{VectorXd(), VectorXd::Ones(nx)});
  row.base.material = scene.material;
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  using solvers::InitialStateBlock;
  auto x0 = std::make_shared<InitialStateBlock>(InitialStateBlock::kPosition, all, InitialStateBlock::kPerNode);
  x0->SetInitial(q0);
  auto v0 = std::make_shared<InitialStateBlock>(InitialStateBlock::kVelocity, all, InitialStateBlock::kPerNode);
  auto activation = std::make_shared<ConstantActivationVariables>(muscles, nx);
  activation->SetInitial(a);
  auto force = std::make_shared<ConstantForceVariables>(3 * n);
  force->SetInitial(f);
  row.variables = {x0, v0, activation, force};
  row.loss = {{std::make_shared<LinearFinalStateLoss>(gq, gv), 1.0}};

  row.budget.optimised = false;
  row.solver.rel_tolerance = 1e-4;
  row.solver.max_iterations = 5000;
  row.solver.paper_threads = -1;
  row.paper.newton_pcg = {118.2, 39.4, {}, {}};
  row.paper.newton_cholesky = {160.1, 55.9, {}, {}};
  row.paper.diffpd = {10.5, 5.5, {}, {}};
  row.paper.speedup = 10;
  row.notes = CommonRowNotes();
  row.notes.push_back(
      "rel_tol: the paper does not say which of its swept values (1e-1 ... 1e-7) the Table used; 1e-4 here");
  row.notes.push_back("variables: the gradient is taken w.r.t. x0, v0, the 32 activations and the force f");
  return row;
}

}  // namespace diffpd::problems
