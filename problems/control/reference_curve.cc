#include "control/reference_curve.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "diffpd/csv_fields.h"
#include "diffpd/error.h"
#include "diffpd/input_file.h"

namespace diffpd::problems {

ReferenceCurve ReadReferenceCurve(const std::string& path, const std::string& label) {
  std::ifstream in = OpenInputFile(path);
  ReferenceCurve curve;
  curve.label = label;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (TrimCsvField(line).empty()) continue;
    const std::vector<std::string> fields = SplitCsvLine(line);
    double x = 0, y = 0;
    if (fields.size() != 2 || !ParseCsvNumber(fields[0], &x) || !ParseCsvNumber(fields[1], &y) || !std::isfinite(x) ||
        !std::isfinite(y)) {
      std::ostringstream msg;
      msg << path << ":" << number << ": expected two finite numbers 'x,y', got '" << TrimCsvField(line) << "'";
      throw InvalidInputError(msg.str());
    }
    curve.points.emplace_back(x, y);
  }
  if (curve.points.empty()) throw InvalidInputError(path + ": no data rows");
  return curve;
}

}  // namespace diffpd::problems
