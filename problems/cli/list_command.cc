#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "diffpd/error.h"
#include "problem_registry.h"

namespace diffpd::problems {

int ListCommand(bool json) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : AllProblems()) {
    if (json)
      out.push_back({{"name", p->name()}, {"description", p->description()}});
    else
      std::printf("%-24s %s\n", p->name().c_str(), p->description().c_str());
  }
  if (json) std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

void RefuseSimulatorTuning(const CommandArgs& args, const std::string& problem) {
  if (args.lbfgs_weight_scale != SolverOptions().lbfgs_weight_scale || !args.rigid_mode_correction)
    throw InvalidInputError("--lbfgs-scale and --no-rigid-correction are not used by the calibration problem '" +
                            problem + "' (it fits with the library's default solver settings)");
  if (args.verbosity != 0)
    throw InvalidInputError("--verbosity is not used by the calibration problem '" + problem +
                            "' (its log is Ceres' iteration table; the simulator stays silent)");
}

SolverOptions OptionsFromArgs(const CommandArgs& args, double default_dt, double default_rel_tolerance) {
  SolverOptions o;
  o.method = args.method;
  o.num_threads = args.threads;
  o.time_step = args.dt > 0 ? args.dt : default_dt;
  o.rel_tolerance = args.rel_tolerance > 0 ? args.rel_tolerance : default_rel_tolerance;
  o.lbfgs_weight_scale = args.lbfgs_weight_scale;
  o.rigid_mode_correction = args.rigid_mode_correction;
  o.verbosity = args.verbosity;
  return o;
}

}  // namespace diffpd::problems
