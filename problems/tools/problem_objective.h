// A problem's own loss and its gradient with respect to the problem's own
// optimisation variables, at a fixed point of those variables, as a function
// of the simulator settings: what `diffpd tradeoff` measures the speed and
// accuracy of. Every loss is evaluated by the rollout core
// (solvers::RolloutFunction, or the Ipopt problem built on it), the same
// code the problem's optimiser calls.
//
//  - paper-<row> (cantilever, rolling-sphere, plant, bouncing-ball, bunny,
//    routing-tendon, torus, quadruped, cow, starfish, shark): the DiffPD paper's rows at their
//    reduced size (RowSize::kSmall; `paper_size`: the paper's) with the
//    Table's masses (the original code's equal node masses; `paper_masses`
//    chooses), loss and variables of the row at its starting point x_init,
//    default method pd-lbfgs (`diffpd table`'s DiffPD column) with the row's
//    settings; preparatory simulations (plant's initial state, the target
//    motions) run once with newton-cholesky at rel_tolerance 1e-10.
//  - routing-tendon, bunny, torus, quadruped, cow (Ipopt problems): the small
//    instance's objective (RolloutNlp::Objective) at its starting point, with
//    the problem's settings and `diffpd run`'s method, pd-lbfgs.
//  - starfish-control, shark-control: the small swimmer's swim loss over the
//    controller's weights (initialisation seed 42).
//  - calibrate-cantilever, calibrate-plant, calibrate-bouncing-ball: the fit's
//    cost 1/2 |r|^2 of the marker residuals against the shipped captured
//    motion, over the fitted material fields at the fit's initial guess.
//  - calibrate-starfish: the default fit's cost 1/2 |r|^2 of the marker
//    residuals on 1.0-1.5 s of the cyclic1 recording (shared data), over its
//    ten fitted values (E, nu, density, the tendon's slack, lag, length and
//    release lag, the water's three coefficients) at the fit's start.
//  - cantilever, falling-cube, cantilever-plane, rolling-sphere,
//    bouncing-ball (forward scenes, no optimisation of their own): the linear
//    loss of bench.h, L = c_x . x_K + c_v . v_K, over [x_0, v_0, E, nu, rho];
//    default settings those of `diffpd run` (pd-lbfgs, rel_tolerance 1e-4).
//
// The small instances' sizes are fixed by their problems; `steps` overrides
// the step count of the forward scenes only.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "diffpd/simulator.h"
#include "diffpd/solver_options.h"

namespace diffpd::problems {

// Changes to a scene's FrictionalContactOptions that an objective with a
// screening knob makes before it measures; a negative value keeps the scene's.
struct ContactOverrides {
  double screening_rel_tolerance = -1;  // the screening solves' tolerance (0: none)
  double max_energy_gain = -1;          // the contact energy guard (contact.h)
};

// One evaluation: loss, gradient and final state at the objective's point.
struct ObjectiveMeasurement {
  std::string failure;                   // "" on success, else why the rollout or its gradient failed
  double forward_s = 0, backward_s = 0;  // wall-clock seconds of the rollout and of its gradient
  double iters_per_step = 0;             // forward solver iterations per step
  double loss = 0;
  VectorXd gradient;     // dL/d(variables)
  VectorXd final_state;  // [x_K; v_K]
  bool ok() const { return failure.empty(); }
};

// One run of a problem's own optimiser from its own start (optimiser_tradeoff.h).
struct OptimiserOutcome {
  std::string failure;   // "" when the optimiser ran to its end; else why it could not
  std::string status;    // how the optimiser ended, in its own words
  double wall_s = 0;     // wall-clock seconds of the whole optimisation
  long evaluations = 0;  // rollouts the optimiser asked for
  int iterations = 0;    // its iterations (Adam: updates)
  // The loss at the start and at the returned point, both re-evaluated with
  // converged settings (newton-cholesky, rel_tolerance 1e-10), and the
  // optimiser's own last value at its tolerance.
  double initial_loss = 0, final_loss = 0, reported_loss = 0;
  // The largest constraint or bound violation at the returned point, as the
  // optimiser saw it (0 for an unconstrained problem).
  double constraint_violation = 0;
  bool ok() const { return failure.empty(); }
};

struct ProblemObjective {
  std::string problem;
  // What the gradient is taken with respect to, in words ("log E, nu (2)").
  std::string variables;
  std::string loss;  // what L is, in words
  // The problem's own settings (method, tolerances, time step): what a user
  // gets without choosing.
  SolverOptions defaults;
  int dofs = 0, steps = 0;
  // A paper row's masses ("equal-nodes" or "lumped"); "" for the other
  // problems (their scenes' own).
  std::string masses;
  // Whether the scene has frictional contact (a screening tolerance to trade)
  // and whether Measure can change its options (ContactOverrides).
  bool frictional_contact = false;
  bool screening_knob = false;
  double screening = 0;  // the scene's own screening_rel_tolerance (where screening_knob)
  // A forward scene (time-step sweep with bench.h's linear loss), and one
  // with a mesh-resolution knob (MakeRefinedProblem).
  bool time_step_knob = false;
  bool resolution_knob = false;
  // Evaluates the loss and its gradient with `options` (the time step is the
  // problem's: options.time_step is ignored) and, where screening_knob, the
  // scene's frictional contact changed as `contact` says. Never throws for a
  // failed rollout (see failure); throws InvalidInputError for invalid
  // options.
  std::function<ObjectiveMeasurement(const SolverOptions& options, const ContactOverrides& contact)> measure;
  // The problem's own optimiser (in words; "" for a forward scene) and one
  // run of it from the problem's start with `options` for every evaluation,
  // stopped after `max_iterations` iterations (<= 0: the problem's own
  // budget). Empty for a forward scene. Never throws for a failed run.
  std::string optimiser;
  std::function<OptimiserOutcome(const SolverOptions& options, int max_iterations)> optimise;
};

// The problems that have an objective here: the registered problems (those of
// this build) and the paper rows (paper-<row>).
std::vector<std::string> ObjectiveProblemNames();
// What `diffpd tradeoff --all` sweeps: ObjectiveProblemNames() without the
// closed-loop paper rows (paper-starfish, paper-shark), whose small instances
// are the bodies, controllers and losses of starfish-control and
// shark-control, which it sweeps already.
std::vector<std::string> AllSweepProblemNames();

// Which instance of a problem MakeProblemObjective builds.
struct ObjectiveInstance {
  int steps = -1;           // > 0: replaces the step count of a forward scene
  int refine = 0;           // cantilever, falling-cube: cell doublings (MakeRefinedProblem)
  bool paper_size = false;  // paper-<row>: the row at the paper's size (RowSize::kPaper), not the reduced one
  // paper-<row>: the body's masses; unset: the Table's (`diffpd table`'s
  // default, kEqualNodes: the original code's), so that a paper row's front
  // is that of the Table's instance.
  std::optional<MassLumping> paper_masses;
};

// The objective of `problem` (a name of ObjectiveProblemNames()) with
// `threads` element-loop threads (0: OpenMP's default), of the instance
// `instance` says. Builds the instance (reads meshes and recorded data, runs
// a paper row's preparatory simulations). Throws InvalidInputError for an
// unknown problem, listing the valid names, for refine != 0 on a problem
// without a resolution knob, and for paper_size or paper_masses on a problem
// that is not a paper row.
ProblemObjective MakeProblemObjective(const std::string& problem, int threads, const ObjectiveInstance& instance = {});

}  // namespace diffpd::problems
