// `diffpd gradcheck`: rollout gradients vs central finite differences, a
// verdict per input kind (tools/gradcheck.h).
#include <chrono>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "diffpd/simulator.h"
#include "problem_registry.h"
#include "tools/gradcheck.h"

namespace diffpd::problems {

int GradcheckCommand(const CommandArgs& args, const GradCheckOptions& check) {
  check.Validate();
  const auto problem = MakeProblem(args.problem);
  const int steps = args.steps > 0 ? args.steps : problem->default_steps();
  SolverOptions options =
      OptionsFromArgs(args, problem->default_time_step(), RecommendedGradCheckRelTolerance(args.method));
  options.abs_tolerance = 1e-12;
  options.max_iterations = RecommendedGradCheckMaxIterations(options.method);
  options.backward_rel_tolerance = 1e-12;
  const Scene scene = problem->MakeScene();
  Simulator sim(scene, options);
  const State initial = problem->InitialState(sim);
  const double problem_time_step = options.time_step;
  if (args.dt <= 0) {
    options.time_step = RecommendedGradCheckTimeStep(scene, sim, initial);
    if (options.time_step != problem_time_step)
      std::fprintf(stderr,
                   "gradcheck %s: %s is unstable at the problem's step %g s (above half its stability limit at the "
                   "initial state); checked at h = %g s (--dt sets the step)\n",
                   problem->name().c_str(), ToString(options.method), problem_time_step, options.time_step);
  }
  std::fprintf(stderr, "gradcheck %s: method %s, %d steps, h = %g s, rtol %g\n", problem->name().c_str(),
               ToString(options.method), steps, options.time_step, options.rel_tolerance);
  // A method that cannot reach the recommended tolerance on this problem
  // within its iterations is checked at the tightest it reaches (up to 1e-6).
  // A line per judged direction: a check of a slow method runs for an hour.
  GradCheckOptions with_progress = check;
  const auto start = std::chrono::steady_clock::now();
  with_progress.progress = [&](const GradCheckProgress& p) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "gradcheck %s: %s direction %d of %d: %s, margin %.3g (%s); %ld perturbed rollouts, %.0f s\n",
                 problem->name().c_str(), p.input.c_str(), p.direction, p.directions, ToString(p.verdict), p.margin,
                 p.basis.c_str(), p.perturbed_rollouts, seconds);
  };
  double rel_tolerance = options.rel_tolerance;
  const GradCheckResult result =
      CheckRolloutGradientAtReachableTolerance(scene, options, initial, steps, with_progress, 1e-6, &rel_tolerance);
  if (rel_tolerance != options.rel_tolerance)
    std::fprintf(stderr,
                 "gradcheck %s: %s does not reach rtol %g within %d iterations per step; checked at rtol %g, the "
                 "tightest it reaches\n",
                 problem->name().c_str(), ToString(options.method), options.rel_tolerance, options.max_iterations,
                 rel_tolerance);
  if (args.json) {
    nlohmann::json out = GradCheckToJson(result);
    out["problem"] = problem->name();
    out["steps"] = steps;
    out["time_step"] = options.time_step;
    out["problem_time_step"] = problem_time_step;
    out["rel_tolerance"] = rel_tolerance;
    out["requested_rel_tolerance"] = options.rel_tolerance;
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("%s", GradCheckTable(result).c_str());
  }
  if (result.verdict == CheckVerdict::kFail) {
    std::fprintf(stderr, "diffpd gradcheck: %d input(s) fail (see the table)\n", result.Count(CheckVerdict::kFail));
    return 4;
  }
  return 0;
}

}  // namespace diffpd::problems
