// Row 7, Torus (open-loop rolling): PROBLEMS.md section 7.
#include <cmath>

#include "diffpd/solvers/core/trajectory_function.h"
#include "paper/activation_variables.h"
#include "paper/paper_meshes.h"
#include "paper/paper_rows.h"

namespace diffpd::problems {

PaperRow MakeTorusRow(RowSize size) {
  const bool paper = size == RowSize::kPaper;
  constexpr int kGroups = 8;
  // Paper: 400 steps, 20 control frames of 20 steps; small: 10 steps, 2 frames of 5.
  const int window = paper ? 20 : 5;
  PaperRow row;
  row.name = "torus";
  row.title = "Torus (open-loop rolling)";
  row.table_index = 7;
  row.size = size;
  row.time_step = 4e-3;
  row.steps = paper ? 400 : 2 * window;

  Scene& scene = row.scene;
  scene.mesh = ReadPaperMesh("torus_analytic.msh", 0.1);
  scene.material = MaterialParameters{5e5, 0.4, 1e3};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  FrictionalContact ground;
  ground.surface = ContactSurface::Plane(Vec3::UnitZ(), 0.0);
  ground.nodes = SingleElementNodes(scene.mesh);
  scene.frictional_contacts = {ground};
  const Mesh& mesh = scene.mesh;
  const int n = mesh.num_vertices();
  // One fibre per element along the ring, (-o_z, 0, o_x) / |.|, o = element
  // centre - mean node; 8 groups by floor(atan2(o_z, o_x) / (pi / 4)) mod 8.
  // Sums in node and corner order, as the original does in numpy and Python:
  // elements on a sector boundary (the diagonals) fall on the side rounding
  // puts them.
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < n; ++i) sum += mesh.vertices.col(i);
  const Vec3 mean = sum / n;
  scene.muscles.resize(kGroups);
  for (Muscle& m : scene.muscles) m.stiffness = 2e5;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    Vec3 centre = Vec3::Zero();
    for (int a = 0; a < 8; ++a) centre += mesh.vertices.col(mesh.elements(a, e));
    const Vec3 o = centre / 8.0 - mean;
    const int sector = static_cast<int>(std::floor(std::atan2(o.z(), o.x()) / (M_PI / 4)));
    Muscle& m = scene.muscles[((sector % kGroups) + kGroups) % kGroups];
    m.elements.push_back(e);
    m.fibers.push_back(Vec3(-o.z(), 0, o.x()).normalized());
  }

  State initial{Eigen::Map<const VectorXd>(mesh.vertices.data(), 3 * n), VectorXd::Zero(3 * n)};
  for (int i = 0; i < n; ++i) initial.v(3 * i) = 0.25;
  row.base.initial = initial;
  row.base.inputs.assign(row.steps, StepInput{VectorXd(), VectorXd::Ones(kGroups)});
  row.base.material = scene.material;
  std::vector<int> groups(kGroups);
  for (int g = 0; g < kGroups; ++g) groups[g] = g;
  auto activation = std::make_shared<WindowedActivationVariables>(groups, kGroups, row.steps, window);
  const int p = activation->size();
  const VectorXd lower = VectorXd::Zero(p), upper = VectorXd::Constant(p, 2.0);
  SetBlockBounds(activation.get(), lower, upper);
  // Seed 42: a first draw (replaced), then the 16 draws that both normalise
  // the loss and give x_init (the best of them).
  NumpyRandom rng(42);
  activation->SetInitial(rng.Uniform(lower, upper));
  row.random_draws = UniformDraws(&rng, lower, upper, 16);
  row.initial_guess = InitialGuess::kBestRandomDraw;
  row.variables = {activation};

  // -xbar_x(x_K), xbar the mean node.
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  row.loss = {{std::make_shared<solvers::PointCoordinate>(solvers::MeanOf(n, all), solvers::kFinalState, Vec3(-1, 0, 0),
                                                          "mean_position_x"),
               1.0}};
  row.baseline = LossBaseline::kDiffPdFinal;

  row.budget.ftol = 1e-3;
  row.budget.max_iterations = 10;
  row.solver.rel_tolerance = 1e-6;
  row.paper.newton_pcg = {751.9, 210.3, 47, -2.3e-3};
  row.paper.newton_cholesky = {719.9, 212.4, 43, -2.4e-2};
  row.paper.diffpd = {84.3, 81.9, 27, 0.0};
  row.paper.speedup = 6;
  row.notes = CommonRowNotes();
  row.notes.push_back(FrictionalContactNote());
  return row;
}

}  // namespace diffpd::problems
