// `diffpd gradcheck`: rollout gradients vs central finite differences.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "diffpd/simulator.h"
#include "tools/gradcheck.h"
#include "problem_registry.h"

namespace diffpd::problems {

int GradcheckCommand(const CommandArgs& args) {
  const auto problem = MakeProblem(args.problem);
  const int steps = args.steps > 0 ? args.steps : problem->default_steps();
  SolverOptions options = OptionsFromArgs(args, problem->default_time_step(), 1e-11);
  options.abs_tolerance = 1e-12;
  options.backward_rel_tolerance = 1e-12;
  const Scene scene = problem->MakeScene();
  Simulator sim(scene, options);
  const State initial = problem->InitialState(sim);
  std::fprintf(stderr, "gradcheck %s: method %s, %d steps, h = %g s, rtol %g\n", problem->name().c_str(),
               ToString(options.method), steps, options.time_step, options.rel_tolerance);
  const GradCheckResult result = CheckRolloutGradient(scene, options, initial, steps);
  if (args.json) {
    nlohmann::json inputs = nlohmann::json::object();
    for (const auto& e : result.inputs)
      inputs[e.input] = {{"max_rel_error", e.max_rel_error}, {"entries", e.entries}, {"directions", e.directions}};
    nlohmann::json out = {{"problem", problem->name()},
                          {"method", ToString(options.method)},
                          {"max_rel_error", result.max_rel_error},
                          {"inputs", inputs}};
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("%-16s %14s %10s %10s\n", "input", "max_rel_error", "entries", "directions");
    for (const auto& e : result.inputs)
      std::printf("%-16s %14.3e %10ld %10d\n", e.input.c_str(), e.max_rel_error, e.entries, e.directions);
    std::printf("%-16s %14.3e\n", "all", result.max_rel_error);
  }
  return 0;
}

}  // namespace diffpd::problems
