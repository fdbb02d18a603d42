#include "calibration/plant_recordings.h"

#include <cmath>

#include "calibration/calibrate_plant.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/core/marker_residuals.h"

namespace diffpd::problems {
namespace {

void CheckIndex(int i, int count) {
  if (count < 1)
    throw InvalidInputError("plant recordings: count = " + std::to_string(count) + " is invalid: must be >= 1");
  if (i < 0 || i >= count)
    throw InvalidInputError("plant recording " + std::to_string(i) + " is out of range [0, " + std::to_string(count) +
                            ")");
}

}  // namespace

Vec3 PlantGust(int i, int count) {
  CheckIndex(i, count);
  const double angle = 2 * M_PI * i / count, c = std::cos(angle), s = std::sin(angle);
  const Vec3 base(0.3, 0.15, 0);
  return Vec3(c * base.x() - s * base.y(), s * base.x() + c * base.y(), 0);
}

CapturedMotion SynthesizePlantRecording(int i, int count) {
  const PlantCalibration plant;
  Scene scene = plant.MakeScene();
  scene.material = plant.truth();
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  options.time_step = plant.default_time_step();
  options.rel_tolerance = 1e-11;
  options.abs_tolerance = 1e-11;
  options.num_threads = 1;
  Simulator sim(scene, options);
  const Rollout truth = sim.Simulate(PlantCalibration::GustState(sim, PlantGust(i, count)),
                                     std::vector<StepInput>(plant.default_steps()));
  return SampleMarkers(scene.mesh, truth.states, plant.default_time_step(), plant.Markers(scene.mesh),
                       plant.CaptureTimes(), plant.noise(), plant.seed() + i);
}

solvers::RolloutTerm PlantRecordingTerm(int i, const PlantRecordingsOptions& options) {
  const CapturedMotion motion = SynthesizePlantRecording(i, options.count);
  const PlantCalibration plant;
  Scene scene = plant.MakeScene();
  scene.material = plant.initial_guess();
  SolverOptions solver = plant.FitOptions(options.method);
  solver.num_threads = options.threads;
  solver.adjoint_solver = AdjointSolver::kIterative;  // deterministic (the automatic choice follows timings)
  const int steps = MarkerObservations::RequiredSteps(motion, solver.time_step);
  auto function = std::make_unique<solvers::RolloutFunction>(scene, solver, steps);
  function->SetInitialState(PlantCalibration::GustState(function->simulator(), PlantGust(i, options.count)));
  const std::vector<solvers::MaterialField> fields = plant.fitted();
  function->AddBlock(std::make_unique<solvers::MaterialBlock>(
      std::vector<solvers::MaterialBlock::Entry>(fields.begin(), fields.end()), scene));
  const int markers =
      function->AddFunctional(std::make_unique<solvers::MarkerResiduals>(motion, scene.mesh, solver.time_step, steps));
  solvers::RolloutTerm term;
  term.rows = function->RowsOf(markers);
  term.function = std::move(function);
  return term;
}

}  // namespace diffpd::problems
