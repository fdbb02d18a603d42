#include "tools/problem_objective.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <numeric>

#include "control/swimmer_control.h"
#include "diffpd/error.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "paper/paper_rows.h"
#include "paper/row_rollout_function.h"
#include "problem_registry.h"
#include "tools/bench.h"
#if DIFFPD_WITH_CERES
#include "calibration/calibrate_problem.h"
#include "calibration/calibrate_starfish.h"
#include "diffpd/captured_motion.h"
#include "shared_data.h"
#endif
#if DIFFPD_WITH_IPOPT
#include "control/trajectory_optimization.h"
#include "diffpd/solvers/ipopt/ipopt_solve.h"
#include "paper/row_optimisation.h"
#endif

namespace diffpd::problems {
namespace {

constexpr const char* kPaperPrefix = "paper-";
constexpr std::uint64_t kSwimmerSeed = 42;  // the controller's initialisation

// Options of the preparatory simulations and of a converged run.
SolverOptions Converged(SolverOptions o) {
  o.method = Method::kNewtonCholesky;
  o.rel_tolerance = kReferenceRelTolerance;
  o.backward_rel_tolerance = kReferenceBackwardRelTolerance;
  o.tolerance_reference = ToleranceReference::kStartResidual;
  return o;
}

double ItersPerStep(const Rollout& r) {
  if (r.reports.empty()) return 0;
  long total = 0;
  for (const auto& s : r.reports) total += s.iterations;
  return static_cast<double>(total) / r.reports.size();
}

// The loss sum_t weights[t] v_{rows[t]} (least_squares: 1/2 sum_r v_r^2 over
// `rows`) of f at p and its gradient: one rollout and one adjoint pass.
ObjectiveMeasurement MeasureFunction(solvers::RolloutFunction* f, const VectorXd& p, const std::vector<int>& rows,
                                     const std::vector<double>& weights, bool least_squares) {
  ObjectiveMeasurement m;
  f->ResetStatistics();
  VectorXd values;
  if (!f->Evaluate(p, rows, &values, nullptr)) {
    m.failure = f->statistics().last_error;
    return m;
  }
  m.forward_s = f->statistics().forward_seconds;
  VectorXd w = VectorXd::Zero(f->num_rows());
  for (size_t t = 0; t < rows.size(); ++t) w(rows[t]) += least_squares ? values(t) : weights[t];
  double value = 0;
  if (!f->Gradient(p, w, &m.gradient, &value)) {
    m.failure = f->statistics().last_error;
    return m;
  }
  // Gradient's value is sum_r v_r^2 for the least-squares weights.
  m.loss = least_squares ? 0.5 * value : value;
  m.backward_s = f->statistics().backward_seconds;
  const Rollout* rollout = f->RolloutAt(p);
  m.final_state = StackState(rollout->states.back());
  m.iters_per_step = ItersPerStep(*rollout);
  return m;
}

// The loss of MeasureFunction at p, without its gradient; false (and
// *failure) when the rollout fails.
bool LossAt(solvers::RolloutFunction* f, const VectorXd& p, const std::vector<int>& rows,
            const std::vector<double>& weights, bool least_squares, double* loss, std::string* failure) {
  VectorXd values;
  if (!f->Evaluate(p, rows, &values, nullptr)) {
    *failure = f->statistics().last_error;
    return false;
  }
  *loss = least_squares ? 0.5 * values.squaredNorm() : 0.0;
  if (!least_squares)
    for (size_t t = 0; t < rows.size(); ++t) *loss += weights[t] * values(t);
  return true;
}

// Runs `body` and turns an exception into the outcome's failure.
OptimiserOutcome Guarded(const std::function<void(OptimiserOutcome*)>& body) {
  OptimiserOutcome out;
  try {
    body(&out);
  } catch (const std::exception& e) {
    out.failure = e.what();
  }
  return out;
}

bool HasFrictionalContact(const Scene& scene) { return !scene.frictional_contacts.empty(); }

void ApplyContactOverrides(Scene* scene, const ContactOverrides& contact) {
  if (contact.screening_rel_tolerance >= 0)
    scene->frictional_contact_options.screening_rel_tolerance = contact.screening_rel_tolerance;
  if (contact.max_energy_gain >= 0) scene->frictional_contact_options.max_energy_gain = contact.max_energy_gain;
}

ProblemObjective PaperRowObjective(const std::string& name, int threads, RowSize size, MassLumping masses) {
  auto row = std::make_shared<PaperRow>(MakePaperRow(name.substr(std::string(kPaperPrefix).size()), size));
  SetRowMasses(row.get(), masses);
  row->Prepare(Converged(row->Options(Method::kNewtonCholesky, threads)));
  ProblemObjective o;
  o.problem = name;
  o.variables = "the row's variables (" + std::to_string(row->num_variables()) + ")";
  o.loss = "the row's loss (" + std::to_string(row->loss.size()) + " terms)";
  o.defaults = row->Options(Method::kPdLbfgs, threads);  // the method of `diffpd table`'s DiffPD column
  o.dofs = row->scene.mesh.num_dofs();
  o.steps = row->steps;
  o.masses = ToString(masses);
  o.frictional_contact = HasFrictionalContact(row->scene);
  o.screening_knob = true;
  o.screening = row->scene.frictional_contact_options.screening_rel_tolerance;
  o.measure = [row](const SolverOptions& options_in, const ContactOverrides& contact) {
    SolverOptions options = options_in;
    options.time_step = row->time_step;
    PaperRow copy = *row;
    ApplyContactOverrides(&copy.scene, contact);
    RowRolloutFunction f = MakeRowRolloutFunction(copy, options);
    return MeasureFunction(f.function.get(), row->initial(), f.loss_rows, f.loss_weights, false);
  };
#if DIFFPD_WITH_IPOPT
  if (!row->budget.optimised) return o;  // a timing-only row (its loss has no minimum to find)
  o.optimiser = "Ipopt with a limited-memory Hessian and the row's bounds (the row's evaluation budget)";
  o.optimise = [row](const SolverOptions& options_in, int max_evaluations) {
    return Guarded([&](OptimiserOutcome* out) {
      SolverOptions options = options_in;
      options.time_step = row->time_step;
      RowOptimisationOptions budget;
      budget.max_evaluations = max_evaluations;
      const RowOptimisationResult r = OptimiseRow(*row, options, budget);
      out->status = r.status + " (" + r.stopped_by + ")";
      out->wall_s = r.total_s;
      out->evaluations = r.evaluations;
      out->iterations = r.iterations;
      out->reported_loss = r.final_loss;
      RowRolloutFunction ref = MakeRowRolloutFunction(*row, Converged(options));
      if (!LossAt(ref.function.get(), row->initial(), ref.loss_rows, ref.loss_weights, false, &out->initial_loss,
                  &out->failure))
        return;
      LossAt(ref.function.get(), r.x, ref.loss_rows, ref.loss_weights, false, &out->final_loss, &out->failure);
    });
  };
#endif
  return o;
}

ProblemObjective SwimmerObjective(const SwimmerControl& problem, int threads) {
  auto swimmer = std::make_shared<Swimmer>(problem.MakeSwimmer(true));
  ProblemObjective o;
  o.problem = problem.name();
  o.loss = "the swim loss";
  o.defaults = problem.BaseOptions(true);
  o.defaults.time_step = swimmer->time_step;
  o.defaults.num_threads = threads;
  o.dofs = swimmer->scene.mesh.num_dofs();
  o.steps = swimmer->steps;
  o.frictional_contact = HasFrictionalContact(swimmer->scene);
  {
    const auto f = MakeSwimmerFunction(*swimmer, o.defaults, kSwimmerSeed);
    o.variables = "the controller's weights (" + std::to_string(f->num_parameters()) + ")";
  }
  o.measure = [swimmer](const SolverOptions& options, const ContactOverrides&) {
    const auto f = MakeSwimmerFunction(*swimmer, options, kSwimmerSeed);
    const std::vector<int> rows = f->RowsOf(0);
    return MeasureFunction(f.get(), f->initial_parameters(), rows, std::vector<double>(rows.size(), 1.0), false);
  };
  o.optimiser = "Adam (the original's settings)";
  const int budget = problem.small_evaluations();
  o.optimise = [swimmer, budget](const SolverOptions& options, int max_evaluations) {
    return Guarded([&](OptimiserOutcome* out) {
      TrainingSettings settings;
      settings.evaluations = max_evaluations > 0 ? max_evaluations : budget;
      settings.seed = kSwimmerSeed;
      const TrainingResult r = TrainSwimmer(*swimmer, options, settings);
      out->status = std::to_string(settings.evaluations) + " evaluations";
      out->wall_s = r.total_seconds;
      out->evaluations = static_cast<long>(r.history.size());
      out->iterations = settings.evaluations;
      out->reported_loss = -r.final_reward();
      const auto ref = MakeSwimmerFunction(*swimmer, Converged(options), kSwimmerSeed);
      const std::vector<int> rows = ref->RowsOf(0);
      const std::vector<double> ones(rows.size(), 1.0);
      if (!LossAt(ref.get(), r.initial_parameters, rows, ones, false, &out->initial_loss, &out->failure)) return;
      LossAt(ref.get(), r.final_parameters, rows, ones, false, &out->final_loss, &out->failure);
    });
  };
  return o;
}

#if DIFFPD_WITH_CERES
ProblemObjective CalibrationObjective(std::shared_ptr<const CalibrationProblem> problem, int threads) {
  auto motion = std::make_shared<CapturedMotion>(ReadCapturedMotion(problem->DefaultDataPath()));
  ProblemObjective o;
  o.problem = problem->name();
  o.loss = "1/2 |r|^2 of the marker residuals";
  o.defaults = problem->FitOptions(problem->default_methods().front());
  o.defaults.num_threads = threads;
  const Scene scene = problem->MakeScene();
  o.dofs = scene.mesh.num_dofs();
  o.frictional_contact = HasFrictionalContact(scene);
  {
    const auto f = problem->MakeModel(*motion, o.defaults);
    o.steps = f->num_steps();
    o.variables = "the fitted material fields (" + std::to_string(f->num_parameters()) + ")";
  }
  o.measure = [problem, motion](const SolverOptions& options_in, const ContactOverrides&) {
    SolverOptions options = options_in;
    options.time_step = problem->default_time_step();
    const auto f = problem->MakeModel(*motion, options);
    return MeasureFunction(f.get(), f->initial_parameters(), f->RowsOf(0), {}, true);
  };
  o.optimiser = "Ceres Levenberg-Marquardt (log E, nu in [0.01, 0.49])";
  o.optimise = [problem, motion](const SolverOptions& options, int max_iterations) {
    return Guarded([&](OptimiserOutcome* out) {
      const CalibrationFit fit =
          problem->Fit(*motion, options, max_iterations > 0 ? max_iterations : problem->max_iterations(), nullptr);
      out->status = fit.termination;
      out->wall_s = fit.total_seconds;
      out->evaluations = fit.statistics.rollouts;
      out->iterations = fit.iterations;
      out->reported_loss = fit.final_cost;
      SolverOptions converged = Converged(options);
      converged.time_step = problem->default_time_step();
      const auto ref = problem->MakeModel(*motion, converged);
      const std::vector<int> rows = ref->RowsOf(0);
      const Eigen::Map<const VectorXd> initial(fit.initial.data(), static_cast<Eigen::Index>(fit.initial.size()));
      const Eigen::Map<const VectorXd> fitted(fit.values.data(), static_cast<Eigen::Index>(fit.values.size()));
      if (!LossAt(ref.get(), initial, rows, {}, true, &out->initial_loss, &out->failure)) return;
      LossAt(ref.get(), fitted, rows, {}, true, &out->final_loss, &out->failure);
    });
  };
  return o;
}

// calibrate-starfish's objective: the default fit's model (E, nu, density,
// the tendon with its asymmetric servo, the water) on the first
// kStarfishObjectiveSeconds of its fit window of the cyclic1 recording, at
// the fit's start.
constexpr double kStarfishObjectiveStart = 1.0;    // s: the default fit window's start
constexpr double kStarfishObjectiveSeconds = 0.5;  // s: the first pull of the tendon (it first moves at 1.18 s)
constexpr int kStarfishObjectiveIterations = 20;   // the default fit's, with the density fitted

ProblemObjective StarfishCalibrationObjective(std::shared_ptr<const StarfishCalibration> problem, int threads) {
  auto recording = std::make_shared<StarfishRecording>(
      ReadStarfishRecording(SharedDataPath("starfish/data_horizontal_cyclic1.csv")));
  auto window = std::make_shared<StarfishWindow>(
      MakeStarfishWindow(*recording, kStarfishObjectiveStart, kStarfishObjectiveSeconds));
  const Scene scene = problem->MakeScene();
  auto guess = std::make_shared<MaterialParameters>(scene.material);
  auto actuation = std::make_shared<StarfishActuation>(StarfishCalibration::ActuationGuess());
  if (problem->release_in_model()) actuation->release_lag = actuation->lag;
  // The model at `options` (its time step is the window's).
  auto model = [problem, recording, window, guess, actuation](const SolverOptions& options) {
    return problem->MakeModel(*recording, *window, options, *guess, *actuation, StarfishCalibration::WaterGuess());
  };
  ProblemObjective o;
  o.problem = problem->name();
  char loss[96];
  std::snprintf(loss, sizeof(loss), "1/2 |r|^2 of the marker residuals (cyclic1, %.1f s to %.1f s)",
                kStarfishObjectiveStart, kStarfishObjectiveStart + kStarfishObjectiveSeconds);
  o.loss = loss;
  o.defaults = problem->Options(Method::kPdLbfgs, threads);
  o.defaults.time_step = StarfishTimeStep(*recording, *window, problem->substeps());
  o.dofs = scene.mesh.num_dofs();
  o.frictional_contact = HasFrictionalContact(scene);
  {
    const auto f = model(o.defaults);
    o.steps = f->num_steps();
    o.variables = "the fitted material, tendon and water values (" + std::to_string(f->num_parameters()) + ")";
  }
  o.measure = [model](const SolverOptions& options, const ContactOverrides&) {
    const auto f = model(options);
    return MeasureFunction(f.get(), f->initial_parameters(), f->RowsOf(0), {}, true);
  };
  o.optimiser = "Ceres Levenberg-Marquardt on the marker residuals (the default fit's values and intervals)";
  o.optimise = [problem, recording, window, guess, actuation, model](const SolverOptions& options, int max_iterations) {
    return Guarded([&](OptimiserOutcome* out) {
      const auto start = std::chrono::steady_clock::now();
      const StarfishFit fit = problem->Fit(*recording, *window, options, *guess, *actuation,
                                           max_iterations > 0 ? max_iterations : kStarfishObjectiveIterations, nullptr);
      out->status = fit.termination;
      out->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      out->evaluations = fit.statistics.rollouts;
      out->iterations = fit.iterations;
      out->reported_loss = fit.final_cost;
      const auto ref = model(Converged(options));
      const std::vector<int> rows = ref->RowsOf(0);
      const std::vector<double> values = StarfishFitValues(fit);
      const Eigen::Map<const VectorXd> fitted(values.data(), static_cast<Eigen::Index>(values.size()));
      if (!LossAt(ref.get(), ref->initial_parameters(), rows, {}, true, &out->initial_loss, &out->failure)) return;
      LossAt(ref.get(), fitted, rows, {}, true, &out->final_loss, &out->failure);
    });
  };
  return o;
}
#endif

#if DIFFPD_WITH_IPOPT
ProblemObjective NlpObjective(std::shared_ptr<const TrajectoryOptimizationProblem> problem, int threads) {
  constexpr InstanceSize kSize = InstanceSize::kSmall;
  ProblemObjective o;
  o.problem = problem->name();
  o.loss = "the Ipopt objective";
  o.defaults = problem->BaseOptions(kSize);
  o.defaults.method = Method::kPdLbfgs;  // `diffpd run`'s default method
  o.defaults.time_step = problem->time_step(kSize);
  o.defaults.num_threads = threads;
  const Scene scene = problem->MakeScene(kSize);
  o.dofs = scene.mesh.num_dofs();
  o.steps = problem->steps(kSize);
  o.frictional_contact = HasFrictionalContact(scene);
  {
    const auto nlp = problem->MakeNlp(o.defaults, kSize);
    o.variables = "the NLP's variables (" + std::to_string(nlp->num_variables()) + ")";
  }
  o.measure = [problem](const SolverOptions& options_in, const ContactOverrides&) {
    SolverOptions options = options_in;
    options.time_step = problem->time_step(kSize);
    Ipopt::SmartPtr<solvers::RolloutNlp> nlp = problem->MakeNlp(options, kSize);
    const VectorXd x = nlp->starting_point();
    ObjectiveMeasurement m;
    if (!nlp->Objective(x, &m.loss)) {
      m.failure = nlp->last_error();
      return m;
    }
    m.forward_s = nlp->statistics().forward_seconds;
    if (!nlp->ObjectiveGradient(x, &m.gradient)) {
      m.failure = nlp->last_error();
      return m;
    }
    m.backward_s = nlp->statistics().backward_seconds;
    const Rollout* rollout = nlp->RolloutAt(x);
    m.final_state = StackState(rollout->states.back());
    m.iters_per_step = ItersPerStep(*rollout);
    return m;
  };
  o.optimiser = "Ipopt with a limited-memory Hessian (the problem's settings)";
  o.optimise = [problem](const SolverOptions& options_in, int max_iterations) {
    return Guarded([&](OptimiserOutcome* out) {
      SolverOptions options = options_in;
      options.time_step = problem->time_step(kSize);
      Ipopt::SmartPtr<solvers::RolloutNlp> nlp = problem->MakeNlp(options, kSize);
      solvers::IpoptOptions ipopt = problem->DefaultIpoptOptions(kSize);
      if (max_iterations > 0) ipopt.int_options.push_back({"max_iter", max_iterations});
      const solvers::IpoptSummary s = solvers::SolveWithIpopt(nlp, ipopt);
      out->status = s.status_name;
      out->wall_s = s.total_seconds;
      out->evaluations = s.evaluations;
      out->iterations = s.iterations;
      out->reported_loss = s.objective;
      out->constraint_violation = s.constraint_violation;
      SolverOptions converged = Converged(options);
      Ipopt::SmartPtr<solvers::RolloutNlp> ref = problem->MakeNlp(converged, kSize);
      if (!ref->Objective(ref->starting_point(), &out->initial_loss) || !ref->Objective(s.x, &out->final_loss))
        out->failure = ref->last_error();
    });
  };
  return o;
}
#endif

// A forward scene: the linear loss of bench.h over [x0, v0, E, nu, rho].
ProblemObjective SceneObjective(std::shared_ptr<const Problem> problem, int threads, int steps_option) {
  ProblemObjective o;
  o.problem = problem->name();
  o.variables = "x_0, v_0, E, nu, rho";
  o.loss = "c_x . x_K + c_v . v_K (random c, seed 20211)";
  o.defaults.time_step = problem->default_time_step();
  o.defaults.method = Method::kPdLbfgs;  // `diffpd run`'s defaults for a forward scene
  o.defaults.rel_tolerance = 1e-4;
  o.defaults.num_threads = threads;
  auto scene = std::make_shared<Scene>(problem->MakeScene());
  o.dofs = scene->mesh.num_dofs();
  o.steps = steps_option > 0 ? steps_option : problem->default_steps();
  o.variables += " (" + std::to_string(2 * o.dofs + 3) + ")";
  o.frictional_contact = HasFrictionalContact(*scene);
  o.screening_knob = true;
  o.screening = scene->frictional_contact_options.screening_rel_tolerance;
  o.time_step_knob = true;
  o.resolution_knob = o.problem == "cantilever" || o.problem == "falling-cube";
  const int steps = o.steps;
  o.measure = [problem, scene, steps](const SolverOptions& options_in, const ContactOverrides& contact) {
    SolverOptions options = options_in;
    options.time_step = problem->default_time_step();
    Scene s = *scene;
    ApplyContactOverrides(&s, contact);
    Simulator sim(s, options);
    const LinearLoss loss = LinearLoss::Random(sim.num_dofs(), 20211);
    const RolloutMeasurement r =
        MeasureRollout(s, options, problem->InitialState(sim), problem->Inputs(sim, steps), loss);
    ObjectiveMeasurement m;
    m.failure = r.failure;
    if (!r.ok()) return m;
    m.forward_s = r.forward_s;
    m.backward_s = r.backward_s;
    m.iters_per_step = r.iters_per_step;
    m.loss = loss.Value(r.final_state);
    m.gradient = r.gradient.head(2 * sim.num_dofs() + 3);
    m.final_state = StackState(r.final_state);
    return m;
  };
  return o;
}

}  // namespace

std::vector<std::string> ObjectiveProblemNames() {
  std::vector<std::string> names;
  for (const auto& p : AllProblems()) {
    names.push_back(p->name());
  }
  for (const auto& row : PaperRowNames()) names.push_back(kPaperPrefix + row);
  return names;
}

std::vector<std::string> AllSweepProblemNames() {
  std::vector<std::string> names;
  for (const auto& n : ObjectiveProblemNames())
    if (n != std::string(kPaperPrefix) + "starfish" && n != std::string(kPaperPrefix) + "shark") names.push_back(n);
  return names;
}

ProblemObjective MakeProblemObjective(const std::string& name, int threads, const ObjectiveInstance& instance) {
  const int steps = instance.steps, refine = instance.refine;
  if (name.rfind(kPaperPrefix, 0) == 0) {
    const std::string row = name.substr(std::string(kPaperPrefix).size());
    for (const auto& r : PaperRowNames())
      if (r == row)
        return PaperRowObjective(name, threads, instance.paper_size ? RowSize::kPaper : RowSize::kSmall,
                                 instance.paper_masses.value_or(MassLumping::kEqualNodes));
  }
  for (auto& p : AllProblems()) {
    if (p->name() != name) continue;
    if (instance.paper_size)
      throw InvalidInputError("the paper's size is invalid for " + name +
                              ": only the paper's rows (paper-<row>) have a paper-size instance");
    if (instance.paper_masses)
      throw InvalidInputError("masses '" + std::string(ToString(*instance.paper_masses)) + "' are invalid for " + name +
                              ": only the paper's rows (paper-<row>) choose their masses");
    if (refine != 0 && name != "cantilever" && name != "falling-cube")
      throw InvalidInputError("refinement = " + std::to_string(refine) + " is invalid for " + name +
                              ": only cantilever and falling-cube have a resolution knob (give 0)");
    std::shared_ptr<const Problem> problem(std::move(p));
    if (auto swimmer = std::dynamic_pointer_cast<const SwimmerControl>(problem))
      return SwimmerObjective(*swimmer, threads);
#if DIFFPD_WITH_CERES
    if (auto calibration = std::dynamic_pointer_cast<const CalibrationProblem>(problem))
      return CalibrationObjective(calibration, threads);
    if (auto starfish = std::dynamic_pointer_cast<const StarfishCalibration>(problem))
      return StarfishCalibrationObjective(starfish, threads);
#endif
#if DIFFPD_WITH_IPOPT
    if (auto nlp = std::dynamic_pointer_cast<const TrajectoryOptimizationProblem>(problem))
      return NlpObjective(nlp, threads);
#endif
    return SceneObjective(refine == 0 ? problem : std::shared_ptr<const Problem>(MakeRefinedProblem(name, refine)),
                          threads, steps);
  }
  std::string valid;
  for (const auto& n : ObjectiveProblemNames()) valid += (valid.empty() ? "" : ", ") + n;
  throw InvalidInputError("problem '" + name + "' has no trade-off objective: valid problems are " + valid);
}

}  // namespace diffpd::problems
