#include "calibration/starfish_trace.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "diffpd/error.h"

namespace diffpd::problems {

std::string WriteStarfishTrace(const std::string& dir, const StarfishRecording& rec, const StarfishWindow& w,
                               const Rollout& rollout, int substeps, const StarfishDisplacements& sim,
                               const StarfishDisplacements& cap) {
  constexpr double kMm = 1e-3;
  std::filesystem::create_directories(dir);
  const std::string path =
      (std::filesystem::path(dir) / (std::filesystem::path(rec.path).stem().string() + "_trace.csv")).string();
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
  out << "time_s,tendon_mm,activation";
  for (int m = 1; m <= 4; ++m) out << ",M" << m << "_sim_x,M" << m << "_cap_x,M" << m << "_sim_z,M" << m << "_cap_z";
  out << "\n";
  for (int j = w.first; j <= w.last; ++j) {
    const int f = j - w.first;
    const int input = std::min(f * substeps, static_cast<int>(rollout.inputs.size()) - 1);
    out << rec.time[j] << "," << rec.tendon[j] / kMm << "," << rollout.inputs[input].activation(0);
    for (int m = 0; m < 4; ++m)
      out << "," << sim[f][m](0) / kMm << "," << cap[f][m](0) / kMm << "," << sim[f][m](1) / kMm << ","
          << cap[f][m](1) / kMm;
    out << "\n";
  }
  return path;
}

}  // namespace diffpd::problems
