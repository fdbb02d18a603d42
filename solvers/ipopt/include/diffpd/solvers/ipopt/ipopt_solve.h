// Runs Ipopt on a RolloutNlp and summarises the outcome.
//
//   Ipopt::SmartPtr<RolloutNlp> nlp =
//       new RolloutNlp(std::make_unique<RolloutFunction>(scene, options, num_steps));
//   ... add variables, objective, constraints ...
//   IpoptOptions options;
//   options.int_options.push_back({"max_iter", 50});
//   IpoptSummary summary = SolveWithIpopt(nlp, options);
//   std::printf("%s\n", summary.BriefReport().c_str());
#pragma once

#include <IpIpoptApplication.hpp>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "diffpd/solvers/ipopt/rollout_nlp.h"
#include "diffpd/solvers/ipopt/rollout_set_nlp.h"

namespace diffpd::solvers {

struct IpoptOptions {
  // Ipopt options, passed to Ipopt unchanged (names and values as in the
  // Ipopt documentation) after this adapter's defaults, so they override
  // them. Defaults set here: hessian_approximation = limited-memory (the
  // NLP has no Hessian), print_level = 5, sb = yes (no banner).
  std::vector<std::pair<std::string, std::string>> string_options;
  std::vector<std::pair<std::string, int>> int_options;
  std::vector<std::pair<std::string, double>> num_options;
  // Ipopt's log is captured into IpoptSummary::log and, if not null, also
  // written here as it is produced (not owned).
  FILE* echo = nullptr;
};

struct IpoptSummary {
  Ipopt::ApplicationReturnStatus status = Ipopt::Internal_Error;
  std::string status_name;          // e.g. "Solve_Succeeded", "Infeasible_Problem_Detected"
  double initial_objective = 0;     // at the starting point (NaN if its rollout failed)
  double objective = 0;             // at the returned point (NaN if its rollout failed)
  double constraint_violation = 0;  // max violation of constraints and bounds at the returned point
  int iterations = 0;               // Ipopt iterations
  long evaluations = 0;             // rollouts (forward simulations), one per evaluation point
  long backward_passes = 0;         // derivative passes: adjoints and tangent passes
  double forward_seconds = 0;       // making setups and simulating during the solve
  double backward_seconds = 0;      // in Simulator::Backward and Simulator::Tangents during the solve
  double total_seconds = 0;         // wall time of the whole solve
  // The returned point: Ipopt's, or, when Ipopt ended without success at a
  // point that is infeasible or worse than the best feasible point it
  // evaluated, that best feasible point (returned_best_feasible = true);
  // the starting point if Ipopt returned none. objective and
  // constraint_violation are those of x.
  VectorXd x;
  bool returned_best_feasible = false;
  std::vector<double> objective_history;  // objective per Ipopt iteration (0 = start)
  std::string log;                        // Ipopt's output at the chosen print_level
  // From derivative_test output: -1 if it did not run, else the number of
  // errors Ipopt's derivative checker reported (0 = "No errors detected").
  int derivative_checker_errors = -1;
  std::string last_error;  // the NLP's last evaluation failure, if any

  // Ipopt found a (locally) optimal or acceptable point.
  bool succeeded() const;
  // Ipopt reported the constraints locally infeasible.
  bool infeasible() const;
  // "Solve_Succeeded: objective 1.2e-03 (from 4.5e-01), violation 1.0e-09, 12 iterations, 15 rollouts, ..."
  std::string BriefReport() const;
};

// "Solve_Succeeded", ... (the enumerator's name).
const char* ToString(Ipopt::ApplicationReturnStatus status);

// Solves `nlp` with Ipopt. Never throws for an Ipopt failure (it is in the
// summary's status); throws InvalidInputError if an option is unknown or
// has an invalid value (Ipopt rejects it), naming the option.
IpoptSummary SolveWithIpopt(const Ipopt::SmartPtr<RolloutNlp>& nlp, const IpoptOptions& options = IpoptOptions());
// SolveWithIpopt over a rollout set's loss (rollout_set_nlp.h): constraint_violation
// is the bounds' violation, never a best feasible point (Ipopt's iterates
// keep the bounds); evaluations, passes and seconds are those of the terms
// evaluated in this process (RolloutSet::statistics).
IpoptSummary SolveRolloutSetWithIpopt(const Ipopt::SmartPtr<RolloutSetNlp>& nlp,
                                      const IpoptOptions& options = IpoptOptions());

}  // namespace diffpd::solvers
