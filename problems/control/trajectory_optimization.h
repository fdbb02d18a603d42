// Trajectory and control optimisation problems solved with Ipopt (DiffPD
// paper Sec. 7.2-7.3): a problem builds a scene and a RolloutNlp over a
// rollout function of it (diffpd/solvers/ipopt/rollout_nlp.h);
// RunOptimization solves it with the chosen simulator method and, for
// comparison, again with Newton-Cholesky, then reports, writes VTK frames of
// the optimised motion and a PNG plot of the objective history.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/solvers/ipopt/ipopt_solve.h"
#include "diffpd/solvers/ipopt/rollout_nlp.h"
#include "problem.h"

namespace diffpd::problems {

// Size of a problem instance.
enum class InstanceSize {
  kFull,   // the paper-like instance
  kSmall,  // coarser mesh, fewer steps and iterations: under a minute for both methods
};

class TrajectoryOptimizationProblem : public Problem {
 public:
  // The scene of an instance (Problem::MakeScene() is the full one).
  virtual Scene MakeScene(InstanceSize size) const = 0;
  virtual int steps(InstanceSize size) const = 0;
  virtual double time_step(InstanceSize size) const = 0;
  // Simulator settings besides method, time step and threads (tolerances).
  virtual SolverOptions BaseOptions(InstanceSize size) const;
  // The optimisation: variables, objective, constraints, over rollouts of
  // MakeScene(size) for `steps(size)` steps simulated with `options`.
  virtual Ipopt::SmartPtr<solvers::RolloutNlp> MakeNlp(const SolverOptions& options, InstanceSize size) const = 0;
  // Ipopt options of the problem (max_iter, tol, ...), before the user's.
  virtual solvers::IpoptOptions DefaultIpoptOptions(InstanceSize size) const;
  // What "improves the objective" means for this problem: the solution's
  // objective must be at most RequiredObjective(initial objective); by
  // default initial - margin * |initial| with improvement_margin() in (0, 1].
  virtual double improvement_margin() const { return 0.5; }
  virtual double RequiredObjective(double initial_objective) const {
    return initial_objective - improvement_margin() * std::abs(initial_objective);
  }
  // The rule in words, for the report.
  virtual std::string improvement_rule() const;

  // `diffpd run <problem>`: solves as the arguments say (--small,
  // --method, --threads, --rtol, --out, --json, --no-compare, --ipopt
  // name=value), prints Ipopt's log and the final table (stderr with --json,
  // whose one JSON object goes to stdout), says so when Ipopt finds the
  // problem infeasible, writes VTK frames, the objective histories, their
  // PNG plot and summary.json into --out (default
  // DefaultOutputDirectory(name())), and returns ExitCode(). --steps and
  // --dt are fixed by the problem (InvalidInputError).
  int Run(const CommandArgs& args) const override;

  // Problem interface: the full instance as a forward simulation.
  Scene MakeScene() const override { return MakeScene(InstanceSize::kFull); }
  int default_steps() const override { return steps(InstanceSize::kFull); }
  double default_time_step() const override { return time_step(InstanceSize::kFull); }
};

struct OptimizationSettings {
  InstanceSize size = InstanceSize::kFull;
  Method method = Method::kPd;  // the simulator method of the main run
  bool compare_newton = true;   // also solve with newton-cholesky (skipped if that is the main method)
  int threads = 0;              // element-loop threads (0: OpenMP default)
  double rel_tolerance = -1;    // simulator rel_tolerance (-1: the problem's)
  double lbfgs_weight_scale = SolverOptions().lbfgs_weight_scale;      // SolverOptions' field of that name
  bool rigid_mode_correction = SolverOptions().rigid_mode_correction;  // SolverOptions' field of that name
  int verbosity = 0;            // SolverOptions::verbosity (the simulator's log on stderr)
  std::string out_dir;          // "": write no files
  FILE* log = stdout;           // Ipopt's iteration log (nullptr: none); not owned
  solvers::IpoptOptions ipopt;  // passed to Ipopt after the problem's defaults
};

struct OptimizationRun {
  Method method = Method::kPd;
  solvers::IpoptSummary summary;
  solvers::DerivativeMode jacobian_mode = solvers::DerivativeMode::kReverse;
  int num_variables = 0, num_constraints = 0, num_dofs = 0, num_steps = 0;
  double required_objective = 0;  // RequiredObjective(initial objective)
  bool improved = false;          // feasible (violation <= 1e-6) and objective <= required_objective
};

struct OptimizationReport {
  std::string problem;
  std::string improvement_rule;
  std::vector<OptimizationRun> runs;  // [0]: the main method; [1]: newton-cholesky when compared
  // Newton-Cholesky's simulation time (forward + backward) over the main
  // method's; 0 if not compared.
  double newton_time_ratio = 0;
  std::vector<std::string> files;  // written files
};

// Runs the problem as the settings say. Throws InvalidInputError for bad
// settings or Ipopt options; an unsuccessful solve is in the report.
OptimizationReport RunOptimization(const TrajectoryOptimizationProblem& problem, const OptimizationSettings& settings);

// The final table (one row per run and the time ratio) and a line saying
// what Ipopt concluded (e.g. that the constraints cannot be met).
void PrintReport(const OptimizationReport& report, FILE* out);
// One sentence about the outcome of a solve, e.g. "Ipopt reports the
// problem infeasible: the constraints cannot be met (Infeasible_Problem_Detected)".
std::string DescribeOutcome(const solvers::IpoptSummary& summary);
// {status, objective, initial_objective, constraint_violation, evaluations,
//  forward_s, backward_s} of the main run, plus problem, method, iterations,
//  improved, jacobian_mode and, when compared, newton_cholesky {same keys}
//  and newton_time_ratio.
nlohmann::json ReportJson(const OptimizationReport& report);

// Parses "name=value" into an Ipopt option: an int if value is an integer,
// a number if it is a floating-point number, else a string. Throws
// InvalidInputError without '=' or with an empty name or value.
void AddIpoptOption(const std::string& name_value, solvers::IpoptOptions* options);

// Where `diffpd run <problem>` writes without --out: out/<problem>
// (relative to the working directory).
std::string DefaultOutputDirectory(const std::string& problem);

// Process exit code of a run: 0 if the main run succeeded, or stopped at
// its iteration limit (small instances cap it on purpose) at a feasible point
// that meets the improvement rule; 4 if Ipopt found the problem infeasible;
// 5 for any other end.
int ExitCode(const OptimizationReport& report);

}  // namespace diffpd::problems
