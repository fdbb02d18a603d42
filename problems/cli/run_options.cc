// RefuseUnusedRunOptions (commands.h): which of `diffpd run`'s
// problem-specific options each kind of problem reads.
#include <string>
#include <vector>

#include "cli/commands.h"
#include "control/swimmer_control.h"
#if DIFFPD_WITH_CERES
#include "calibration/calibrate_problem.h"
#include "calibration/calibrate_starfish.h"
#endif
#if DIFFPD_WITH_IPOPT
#include "control/trajectory_optimization.h"
#endif
#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

enum Kind { kSimulation = 1, kOptimisation = 2, kCalibration = 4, kStarfish = 8, kControl = 16 };

const char* KindName(int kind) {
  switch (kind) {
    case kOptimisation:
      return "optimisation problem";
    case kCalibration:
      return "calibration problem";
    case kStarfish:
      return "starfish calibration";
    case kControl:
      return "control problem";
    default:
      return "simulation problem";
  }
}

int KindOf(const Problem& problem) {
#if DIFFPD_WITH_IPOPT
  if (dynamic_cast<const TrajectoryOptimizationProblem*>(&problem)) return kOptimisation;
#endif
#if DIFFPD_WITH_CERES
  if (dynamic_cast<const CalibrationProblem*>(&problem)) return kCalibration;
  if (dynamic_cast<const StarfishCalibration*>(&problem)) return kStarfish;
#endif
  if (dynamic_cast<const SwimmerControl*>(&problem)) return kControl;
  return kSimulation;
}

// An option, whether it was given, and the kinds of problem that read it.
struct RunOption {
  const char* name;
  bool given;
  int readers;
  const char* read_by;
};

}  // namespace

void RefuseUnusedRunOptions(const CommandArgs& args, const Problem& problem) {
  const CommandArgs defaults;
  const RunOption options[] = {
      {"--small", args.small, kOptimisation | kControl, "the optimisation and control problems"},
      {"--no-compare", args.compare_newton != defaults.compare_newton, kOptimisation | kCalibration | kControl,
       "the optimisation, calibration and control problems"},
      {"--ipopt", !args.ipopt_options.empty(), kOptimisation, "the optimisation problems"},
      {"--evaluations", args.evaluations != defaults.evaluations, kControl, "the control problems"},
      {"--seed", args.seed != defaults.seed, kControl, "the control problems"},
      {"--optimizer", !args.optimizer.empty(), kControl, "the control problems"},
      {"--data", !args.data_file.empty(), kCalibration, "calibrate-plant and calibrate-bouncing-ball"},
      {"--methods", !args.methods.empty(), kCalibration | kStarfish, "the calibration problems"},
      {"--max-iterations", args.max_iterations != defaults.max_iterations, kCalibration | kStarfish,
       "the calibration problems"},
      {"--calibrate", !args.calibrate_file.empty(), kStarfish, "calibrate-starfish"},
      {"--predict", !args.predict_files.empty(), kStarfish, "calibrate-starfish"},
      {"--seconds", args.seconds != defaults.seconds, kStarfish, "calibrate-starfish"},
      {"--regions", !args.regions.empty(), kStarfish, "calibrate-starfish"},
      {"--fit", !args.fit.empty(), kStarfish, "calibrate-starfish"},
      {"--fit-start", args.fit_start != defaults.fit_start, kStarfish, "calibrate-starfish"},
      {"--fit-seconds", args.fit_seconds != defaults.fit_seconds, kStarfish, "calibrate-starfish"},
      {"--water", !args.water.empty(), kStarfish, "calibrate-starfish"},
      {"--servo", !args.servo.empty(), kStarfish, "calibrate-starfish"},
      {"--starts", args.starts != defaults.starts, kStarfish, "calibrate-starfish"},
      {"--density", !args.density.empty(), kStarfish, "calibrate-starfish"},
      {"--damping", !args.damping.empty(), kStarfish, "calibrate-starfish"},
  };
  const int kind = KindOf(problem);
  for (const RunOption& o : options)
    if (o.given && !(o.readers & kind))
      throw InvalidInputError(std::string(o.name) + " is not used by the " + KindName(kind) + " '" + problem.name() +
                              "' (only " + o.read_by + " read it)");
}

}  // namespace diffpd::problems
