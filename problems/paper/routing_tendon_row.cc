// Row 6, Routing tendon (static activation): PROBLEMS.md section 6.
#include "diffpd/box_mesh.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "paper/activation_variables.h"
#include "paper/paper_meshes.h"
#include "paper/paper_rows.h"

namespace diffpd::problems {

PaperRow MakeRoutingTendonRow(RowSize size) {
  const bool paper = size == RowSize::kPaper;
  PaperRow row;
  row.name = "routing-tendon";
  row.title = "Routing tendon (static activation)";
  row.table_index = 6;
  row.size = size;
  row.time_step = 0.01;
  row.steps = paper ? 100 : 5;

  // 4 x 4 x 32 cells of 2.5 cm (the small instance is the same column).
  const int nx = 4, ny = 4, nz = 32;
  Scene& scene = row.scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(nx, ny, nz), Vec3(0.1, 0.1, 0.8));
  scene.material = MaterialParameters{5e5, 0.45, 1e3};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  FixNodes(&scene, NodesWhere(scene.mesh, [](const Vec3& p) { return p.z() <= 1e-9; }));
  // 16 groups of 32 elements: x half i, y half j, z segment s of 8 cells,
  // numbered (2 i + j) 4 + s; element (x ny + y) nz + z is cell (x, y, z).
  scene.muscles.resize(16);
  for (Muscle& m : scene.muscles) {
    m.fibers = {Vec3::UnitZ()};
    m.stiffness = 1e5;
  }
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < ny; ++y)
      for (int z = 0; z < nz; ++z)
        scene.muscles[(2 * (x / 2) + y / 2) * 4 + z / 8].elements.push_back((x * ny + y) * nz + z);
  const int n = scene.mesh.num_vertices();

  row.base.initial = State{Eigen::Map<const VectorXd>(scene.mesh.vertices.data(), 3 * n), VectorXd::Zero(3 * n)};
  row.base.inputs.assign(row.steps, StepInput{VectorXd(), VectorXd::Ones(16)});
  row.base.material = scene.material;
  std::vector<int> groups(16);
  for (int g = 0; g < 16; ++g) groups[g] = g;
  auto activation = std::make_shared<ConstantActivationVariables>(groups, 16);
  const VectorXd lower = VectorXd::Zero(16), upper = VectorXd::Constant(16, 2.0);
  SetBlockBounds(activation.get(), lower, upper);
  // Seed 42: x_init (16 draws), then 16 normalisation draws.
  NumpyRandom rng(42);
  activation->SetInitial(rng.Uniform(lower, upper));
  row.random_draws = UniformDraws(&rng, lower, upper, 16);
  row.variables = {activation};

  // (1/2) |p(x_K) - (0.2, 0.2, 0.45)|^2 / 0.025^2, p the last node (the tip
  // corner at (0.1, 0.1, 0.8)).
  row.loss = {{std::make_shared<solvers::PointDistanceSquared>(solvers::NodePoint(n, n - 1), solvers::kFinalState,
                                                               Vec3(0.2, 0.2, 0.45), "tip_to_target"),
               0.5 / (0.025 * 0.025)}};

  row.budget.ftol = 1e-3;
  row.solver.rel_tolerance = 1e-4;
  row.solver.paper_threads = 0;
  row.paper.newton_pcg = {108.2, 56.7, 36, 6.0e-4};
  row.paper.newton_cholesky = {107.3, 58.7, 38, 4.9e-4};
  row.paper.diffpd = {8.3, 9.9, 30, 9.6e-4};
  row.paper.speedup = 9;
  row.notes = CommonRowNotes();
  return row;
}

}  // namespace diffpd::problems
