#include "calibration/starfish_recording.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "diffpd/captured_motion.h"
#include "diffpd/csv_fields.h"
#include "diffpd/error.h"
#include "diffpd/input_file.h"

namespace diffpd::problems {
namespace {

constexpr double kMm = 1e-3;
const char* const kColumns[10] = {"time", "tendon", "M1 x", "M1 y", "M2 x", "M2 y", "M3 x", "M3 y", "M4 x", "M4 y"};

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

StarfishRecording ReadStarfishRecording(const std::string& path) {
  std::ifstream in = OpenInputFile(path);
  StarfishRecording rec;
  rec.path = path;
  std::string line;
  int number = 0;
  if (!std::getline(in, line)) throw InvalidInputError(path + ": empty file (expected a header row and data rows)");
  ++number;
  {
    const std::vector<std::string> header = SplitCsvLine(line);
    if (header.size() != 10)
      throw InvalidInputError(path + ":1: expected a header row of 10 column labels, got " +
                              std::to_string(header.size()) + " fields");
    double v;
    if (ParseCsvNumber(header[0], &v))
      throw InvalidInputError(path + ":1: expected a header row of column labels, got the number '" + header[0] + "'");
  }
  while (std::getline(in, line)) {
    ++number;
    if (TrimCsvField(line).empty()) continue;
    const std::string where = path + ":" + std::to_string(number) + ": ";
    const std::vector<std::string> fields = SplitCsvLine(line);
    if (fields.size() != 10)
      throw InvalidInputError(where + "expected 10 fields (time ms, tendon mm, M1 x, M1 y, ..., M4 x, M4 y), got " +
                              std::to_string(fields.size()));
    double v[10];
    for (int c = 0; c < 10; ++c)
      if (!ParseCsvNumber(fields[c], &v[c]))
        throw InvalidInputError(where + kColumns[c] + " is not a number: '" + fields[c] + "'");
    if (!std::isfinite(v[0]))
      throw InvalidInputError(where + "time = " + Num(v[0]) + " is invalid: must be finite (ms)");
    if (std::isinf(v[1]))
      throw InvalidInputError(where + "tendon = " + Num(v[1]) + " is invalid: must be finite or NaN (mm)");
    for (int c = 2; c < 10; ++c)
      if (!(std::isfinite(v[c]) && std::abs(v[c] * kMm) <= kMaxMarkerCoordinate))
        throw InvalidInputError(where + kColumns[c] + " = " + Num(v[c]) +
                                " is invalid: marker coordinates must be finite and within +-" +
                                Num(kMaxMarkerCoordinate / kMm) + " (mm)");
    if (!rec.time.empty() && v[0] * kMm <= rec.time.back())
      throw InvalidInputError(where + "time " + Num(v[0]) + " ms is not after the previous row's " +
                              Num(rec.time.back() / kMm) + " ms (line " + std::to_string(rec.lines.back()) + ")");
    rec.time.push_back(v[0] * kMm);
    rec.tendon.push_back(v[1] * kMm);
    std::array<double, 8> m;
    for (int c = 0; c < 8; ++c) m[c] = v[c + 2] * kMm;
    rec.markers.push_back(m);
    rec.lines.push_back(number);
  }
  if (rec.time.empty()) throw InvalidInputError(path + ": no data rows");
  return rec;
}

StarfishWindow MakeStarfishWindow(const StarfishRecording& rec, double start, double seconds) {
  if (!(std::isfinite(seconds) && seconds > 0))
    throw InvalidInputError("seconds = " + Num(seconds) + " is invalid: must be finite and > 0 (s)");
  if (!(std::isfinite(start) && start >= 0))
    throw InvalidInputError("window start = " + Num(start) + " is invalid: must be finite and >= 0 (s)");
  StarfishWindow w;
  const double t0 = rec.time.front() + start;
  w.first = 0;
  while (w.first < rec.num_rows() && rec.time[w.first] < t0 - 1e-9) ++w.first;
  if (w.first == rec.num_rows())
    throw InvalidInputError(rec.path + ": no row at or after " + Num(start) + " s (the recording lasts " +
                            Num(rec.time.back() - rec.time.front()) + " s)");
  if (std::isnan(rec.tendon[w.first]))
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[w.first]) +
                            ": tendon contraction is NaN at the window's first row (t = " + Num(rec.time[w.first]) +
                            " s): nothing to simulate");
  const double end = rec.time[w.first] + seconds;
  w.last = w.first;
  while (w.last + 1 < rec.num_rows() && rec.time[w.last + 1] <= end + 1e-9 && !std::isnan(rec.tendon[w.last + 1]))
    ++w.last;
  if (w.last + 1 < rec.num_rows() && rec.time[w.last + 1] <= end + 1e-9) {
    std::ostringstream note;
    note << rec.path << ":" << rec.lines[w.last + 1] << ": tendon contraction is NaN from t = " << rec.time[w.last + 1]
         << " s; the window stops before it (" << rec.time[w.last] - rec.time[w.first] << " s instead of " << seconds
         << " s)";
    w.note = note.str();
  } else if (w.last + 1 == rec.num_rows() && rec.time[w.last] < end - 0.5 / kStarfishFrameRate) {
    std::ostringstream note;
    note << rec.path << ": the recording ends " << rec.time[w.last] - rec.time[w.first]
         << " s after the window's start (asked for " << seconds << " s)";
    w.note = note.str();
  }
  if (w.last == w.first)
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[w.first]) +
                            ": the window has a single usable row; need at least two");
  return w;
}

double StarfishTimeStep(const StarfishRecording& rec, const StarfishWindow& w, int substeps) {
  return (rec.time[w.last] - rec.time[w.first]) / (w.num_frames() - 1) / substeps;
}

}  // namespace diffpd::problems
