// A learning curve of the original code (learning_curves/*.csv of the shared
// paper data: x = simulated steps, y = reward), drawn beside a run's curve.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace diffpd::problems {

struct ReferenceCurve {
  std::string label;
  std::vector<std::pair<double, double>> points;  // (x, y) in file order
};

// Reads "x,y" rows (two finite numbers per line, blank lines skipped; no
// header). Throws InvalidInputError naming the file and line:
//   "cannot open '<path>'", "cannot open '<path>': it is a directory, not a file",
//   "<path>:3: expected two finite numbers 'x,y', got '1,abc'",
//   "<path>: no data rows".
ReferenceCurve ReadReferenceCurve(const std::string& path, const std::string& label);

}  // namespace diffpd::problems
