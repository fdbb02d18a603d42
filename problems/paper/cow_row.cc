// Row 9, Cow (gait parameters, "pronk"): PROBLEMS.md section 9.
#include <cmath>

#include "diffpd/solvers/core/trajectory_function.h"
#include "paper/activation_variables.h"
#include "paper/paper_meshes.h"
#include "paper/paper_rows.h"

namespace diffpd::problems {

PaperRow MakeCowRow(RowSize size) {
  const bool paper = size == RowSize::kPaper;
  PaperRow row;
  row.name = "cow";
  row.title = "Cow (gait parameters)";
  row.table_index = 9;
  row.size = size;
  row.time_step = 1e-3;
  row.steps = paper ? 575 : 5;

  const double dx = 0.1 / 15;
  Scene& scene = row.scene;
  scene.mesh = ReadPaperMesh("spot.msh", 0.1);
  scene.material = MaterialParameters{1e6, 0.49, 700};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  const Mesh& mesh = scene.mesh;
  FrictionalContact ground;
  ground.surface = ContactSurface::Plane(Vec3::UnitZ(), 0.0);
  ground.nodes = NodesWhere(mesh, [&](const Vec3& p) { return p.z() < dx / 2; });
  scene.frictional_contacts = {ground};
  // Leg cells: z < 4, x in {1, 2} (rear) or {8, 9} (front), y in {1, 2}
  // (right) or {5, 6} (left); x = 2 or 9 pulls forward ("F"), x = 1 or 8
  // back ("B"). Muscle index 4 front + 2 forward + left: RRB, RLB, RRF, RLF,
  // FRB, FLB, FRF, FLF.
  scene.muscles.resize(8);
  for (Muscle& m : scene.muscles) {
    m.fibers = {Vec3::UnitZ()};
    m.stiffness = 5e5;
  }
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Eigen::Vector3i c = ElementCell(mesh, e, dx);
    const bool rear = c.x() == 1 || c.x() == 2, front = c.x() == 8 || c.x() == 9;
    const bool right = c.y() == 1 || c.y() == 2, left = c.y() == 5 || c.y() == 6;
    if (c.z() >= 4 || !(rear || front) || !(right || left)) continue;
    const bool forward = c.x() == 2 || c.x() == 9;
    scene.muscles[4 * front + 2 * forward + left].elements.push_back(e);
  }
  std::vector<GaitActivationVariables::GaitMuscle> gait;
  for (int m = 0; m < 8; ++m) gait.push_back({m, m >= 4, (m & 2) != 0});
  const int n = mesh.num_vertices();

  row.base.initial = State{Eigen::Map<const VectorXd>(mesh.vertices.data(), 3 * n), VectorXd::Zero(3 * n)};
  row.base.inputs.assign(row.steps, StepInput{VectorXd(), VectorXd::Ones(8)});
  row.base.material = scene.material;
  auto activation = std::make_shared<GaitActivationVariables>(gait, 8, row.steps, 1.49);
  const VectorXd lower = Eigen::Vector3d(0.0, 0.0, 2 * M_PI / 575);
  const VectorXd upper = Eigen::Vector3d(1.45, 0.85, 2 * M_PI / 12);
  SetBlockBounds(activation.get(), lower, upper);
  // Seed 42: x_init (3 draws), then 16 normalisation draws.
  NumpyRandom rng(42);
  activation->SetInitial(rng.Uniform(lower, upper));
  row.random_draws = UniformDraws(&rng, lower, upper, 16);
  row.variables = {activation};

  // -xbar_x(x_K) - 0.4 xbar_z(x_K), xbar the mean node.
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  row.loss = {{std::make_shared<solvers::PointCoordinate>(solvers::MeanOf(n, all), solvers::kFinalState,
                                                          Vec3(-1, 0, -0.4), "mean_position_forward_up"),
               1.0}};
  row.baseline = LossBaseline::kDiffPdFinal;

  row.budget.ftol = 1e-2;
  row.budget.max_iterations = 25;
  row.solver.rel_tolerance = 1e-6;
  row.paper.newton_pcg = {771.7, 141.7, 14, 9.7e-1};
  row.paper.newton_cholesky = {620.1, 140.2, 20, 9.8e-1};
  row.paper.diffpd = {105.3, 43.7, 31, 0.0};
  row.paper.speedup = 5;
  row.notes = CommonRowNotes();
  row.notes.push_back(FrictionalContactNote());
  return row;
}

}  // namespace diffpd::problems
