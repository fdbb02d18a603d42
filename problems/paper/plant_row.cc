// Row 3, Plant (material identification): PROBLEMS.md section 3.
#include <cmath>

#include "paper/log_material_variables.h"
#include "paper/paper_meshes.h"
#include "paper/paper_rows.h"
#include "paper/trajectory_losses.h"

namespace diffpd::problems {
namespace {

constexpr double kDx = 1.0 / 86;  // the mesh's cell size (m)

}  // namespace

PaperRow MakePlantRow(RowSize size) {
  const bool paper = size == RowSize::kPaper;
  PaperRow row;
  row.name = "plant";
  row.title = "Plant (material identification)";
  row.table_index = 3;
  row.size = size;
  row.time_step = 0.01;
  row.steps = paper ? 200 : 4;

  Scene& scene = row.scene;
  scene.mesh = ReadPaperMesh("plant.msh");
  // Small: the pot and the stem's lowest 8 cells.
  if (!paper) {
    const Mesh full = scene.mesh;
    scene.mesh = KeepElements(full, [&](int e) { return ElementCentre(full, e).z() < 8 * kDx; });
  }
  const MaterialParameters truth{1e6, 0.4, 5e3};
  scene.material = truth;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  FixNodes(&scene, NodesWhere(scene.mesh, [](const Vec3& p) { return p.z() < kDx / 2; }));
  const int n = scene.mesh.num_vertices();

  row.base.initial = State{VectorXd::Zero(3 * n), VectorXd::Zero(3 * n)};  // set by prepare
  row.base.inputs.assign(row.steps, StepInput{});
  row.base.material = truth;
  using Field = LogMaterialVariables::Field;
  auto material =
      std::make_shared<LogMaterialVariables>(std::vector<Field>{Field::kYoungsModulus, Field::kPoissonsRatio}, truth);
  const VectorXd lower = Eigen::Vector2d(std::log(1e4), std::log(0.2));
  const VectorXd upper = Eigen::Vector2d(std::log(5e6), std::log(0.45));
  SetBlockBounds(material.get(), lower, upper);
  // Seed 42: x_init (2 draws), then 16 normalisation draws.
  NumpyRandom rng(42);
  material->SetInitial(rng.Uniform(lower, upper));
  row.random_draws = UniformDraws(&rng, lower, upper, 16);
  row.variables = {material};

  // q0: 3 steps of 10 ms from rest pushed by -1 N along x on every node
  // (ground truth); the target: the row's steps from (q0, 0), ground truth.
  row.prepare = [](PaperRow* r, const SolverOptions& options) {
    Simulator sim(r->scene, options);
    const int dofs = sim.num_dofs();
    StepInput push;
    push.external_force = VectorXd::Zero(dofs);
    for (int i = 0; i < dofs / 3; ++i) push.external_force(3 * i) = -1.0;
    State s = sim.RestState();
    for (int k = 0; k < 3; ++k) s = sim.Step(s, push);
    s.v.setZero();
    r->base.initial = s;
    const Rollout target = sim.Simulate(s, std::vector<StepInput>(r->steps));
    std::vector<VectorXd> targets;
    for (int k = 1; k <= r->steps; ++k) targets.push_back(target.states[k].x);
    r->loss = {{std::make_shared<TrajectoryTrackingLoss>(std::move(targets)), 1.0}};
  };

  row.budget.ftol = 1e-2;
  row.budget.max_iterations = 10;
  row.solver.rel_tolerance = 1e-4;
  row.paper.newton_pcg = {1089.5, 530.5, 10, 1.9e-3};
  row.paper.newton_cholesky = {929.6, 525.2, 10, 1.9e-3};
  row.paper.diffpd = {71.6, 94.7, 28, 5.9e-7};
  row.paper.speedup = 9;
  row.notes = CommonRowNotes();
  row.notes.push_back("target and initial push simulated with pd-lbfgs at the row's tolerance");
  return row;
}

}  // namespace diffpd::problems
