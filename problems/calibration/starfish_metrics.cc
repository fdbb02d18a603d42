#include "calibration/starfish_metrics.h"

#include <cmath>
#include <string>

#include "diffpd/error.h"

namespace diffpd::problems {

StarfishDisplacements CapturedDisplacements(const StarfishRecording& rec, const StarfishWindow& w) {
  StarfishDisplacements out(w.num_frames());
  const std::array<double, 8>& ref = rec.markers[w.first];
  for (int j = w.first; j <= w.last; ++j)
    for (int m = 0; m < 4; ++m)
      out[j - w.first][m] =
          Eigen::Vector2d(rec.markers[j][2 * m] - ref[2 * m], -(rec.markers[j][2 * m + 1] - ref[2 * m + 1]));
  return out;
}

StarfishDisplacements SimulatedDisplacements(const std::array<int, 4>& vertices, const std::vector<State>& states,
                                             int substeps, int frames) {
  if (frames < 1 || static_cast<int>(states.size()) < (frames - 1) * substeps + 1)
    throw InvalidInputError("SimulatedDisplacements: " + std::to_string(states.size()) + " states do not cover " +
                            std::to_string(frames) + " frames of " + std::to_string(substeps) + " steps");
  StarfishDisplacements out(frames);
  for (int j = 0; j < frames; ++j) {
    const State& s = states[j * substeps];
    for (int m = 0; m < 4; ++m) {
      const int v = vertices[m];
      out[j][m] = Eigen::Vector2d(s.x(3 * v) - states[0].x(3 * v), s.x(3 * v + 2) - states[0].x(3 * v + 2));
    }
  }
  return out;
}

StarfishErrors CompareDisplacements(const StarfishDisplacements& sim, const StarfishDisplacements& cap) {
  if (sim.size() != cap.size())
    throw InvalidInputError("CompareDisplacements: " + std::to_string(sim.size()) + " predicted frames against " +
                            std::to_string(cap.size()) + " captured ones");
  double total_weight = 0;
  for (double wm : kStarfishMarkerWeights) total_weight += wm;
  double sum = 0, sum_rel = 0, sum_w = 0;
  StarfishErrors out;
  for (size_t j = 1; j < sim.size(); ++j) {
    double mean_sim = 0, mean_cap = 0;
    for (int m = 0; m < 4; ++m) {
      mean_sim += sim[j][m](0) / 4;
      mean_cap += cap[j][m](0) / 4;
    }
    for (int m = 0; m < 4; ++m) {
      const Eigen::Vector2d e = sim[j][m] - cap[j][m];
      sum += e.squaredNorm();
      sum_w += kStarfishMarkerWeights[m] * e.squaredNorm() / total_weight;
      sum_rel += (e - Eigen::Vector2d(mean_sim - mean_cap, 0)).squaredNorm();
    }
    ++out.frames;
  }
  if (out.frames > 0) {
    out.rmse = std::sqrt(sum / (4.0 * out.frames));
    out.arm_relative_rmse = std::sqrt(sum_rel / (4.0 * out.frames));
    out.weighted_rms = std::sqrt(sum_w / out.frames);
  }
  return out;
}

StarfishBaselines BaselineErrors(const StarfishDisplacements& cap) {
  std::array<Eigen::Vector2d, 4> zero, mean;
  for (int m = 0; m < 4; ++m) zero[m] = mean[m] = Eigen::Vector2d::Zero();
  for (size_t j = 1; j < cap.size(); ++j)
    for (int m = 0; m < 4; ++m) mean[m] += cap[j][m] / static_cast<double>(cap.size() - 1);
  StarfishDisplacements still(cap.size(), zero), held(cap.size(), mean);
  held[0] = zero;
  return StarfishBaselines{CompareDisplacements(still, cap), CompareDisplacements(held, cap)};
}

}  // namespace diffpd::problems
