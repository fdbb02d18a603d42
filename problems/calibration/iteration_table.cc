#include "calibration/iteration_table.h"

namespace diffpd::problems {

ceres::CallbackReturnType IterationTable::operator()(const ceres::IterationSummary& s) {
  if (s.iteration == 0) {
    std::fprintf(log_, "%4s %13s %11s %11s %11s %10s %9s %9s", "iter", "cost", "cost_change", "|gradient|", "|step|",
                 "tr_radius", "iter_time", "total_t");
    for (solvers::MaterialField p : fitted_) std::fprintf(log_, " %14s", ToString(p));
    std::fprintf(log_, "\n");
  }
  std::fprintf(log_, "%4d %13.6e %11.3e %11.3e %11.3e %10.3e %9.2e %9.2e", s.iteration, s.cost, s.cost_change,
               s.gradient_max_norm, s.step_norm, s.trust_region_radius, s.iteration_time_in_seconds,
               s.cumulative_time_in_seconds);
  for (size_t i = 0; i < fitted_.size(); ++i) std::fprintf(log_, " %14.6g", block_[i]);
  std::fprintf(log_, "%s\n", s.step_is_successful || s.iteration == 0 ? "" : "  (rejected)");
  std::fflush(log_);
  return ceres::SOLVER_CONTINUE;
}

}  // namespace diffpd::problems
