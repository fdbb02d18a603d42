// `diffpd synth <problem> [--dir DIR]`: regenerates the synthetic captured
// motion of a calibration problem (the files shipped in data/).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#if DIFFPD_WITH_CERES
#include "calibration/calibrate_problem.h"
#endif
#include "cli/commands.h"
#include "diffpd/error.h"
#include "problem_registry.h"

namespace diffpd::problems {

Subcommand AddSynthCommand(CLI::App* parent) {
  struct Args {
    std::string problem;
    std::string dir = "data";
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = parent->add_subcommand(
      "synth", "write the synthetic captured motion of a calibration problem (noisy and clean CSV)");
  cmd->add_option("problem", args->problem,
                  "a calibration problem (calibrate-cantilever, calibrate-plant, calibrate-bouncing-ball)")
      ->required();
  cmd->add_option("--dir", args->dir, "output directory")->capture_default_str();
  Subcommand sub;
  sub.app = cmd;
  sub.run = [args]() -> int {
#if DIFFPD_WITH_CERES
    const std::unique_ptr<Problem> problem = MakeProblem(args->problem);
    const auto* calibration = dynamic_cast<const CalibrationProblem*>(problem.get());
    if (!calibration)
      throw InvalidInputError("problem '" + args->problem +
                              "' has no synthetic captured motion (not a calibration problem)");
    for (const std::string& path : calibration->WriteSyntheticData(args->dir)) std::printf("wrote %s\n", path.c_str());
    return 0;
#else
    throw InvalidInputError(
        "diffpd synth: this diffpd was built without the Ceres adapter (DIFFPD_WITH_CERES), "
        "so it has no calibration problem");
#endif
  };
  return sub;
}

}  // namespace diffpd::problems
