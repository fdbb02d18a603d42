#include "cli/option_checks.h"

#include <omp.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/solver_options.h"

namespace diffpd::problems {
namespace {

bool ParseLong(const std::string& s, long* value) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *value = std::strtol(s.c_str(), &end, 10);
  return end == s.c_str() + s.size() && errno == 0;
}

bool ParseDouble(const std::string& s, double* value) {
  if (s.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

// A validator that accepts the values `ok` accepts and throws
// "<option> = <value> is invalid: must be <range>" for the others.
CLI::Validator Rule(const std::string& option, const std::string& range, std::function<bool(const std::string&)> ok) {
  return CLI::Validator(
      [option, range, ok](std::string& value) -> std::string {
        if (!ok(value)) throw InvalidInputError(option + " = " + value + " is invalid: must be " + range);
        return "";
      },
      range);
}

}  // namespace

CLI::Validator IntegerIn(const std::string& option, long min, long max, const std::string& note) {
  std::string range = "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  if (!note.empty()) range += " (" + note + ")";
  return Rule(option, range, [min, max](const std::string& s) {
    long v = 0;
    return ParseLong(s, &v) && v >= min && v <= max;
  });
}

CLI::Validator IntegerAtLeast(const std::string& option, long min) {
  return Rule(option, "an integer >= " + std::to_string(min), [min](const std::string& s) {
    long v = 0;
    return ParseLong(s, &v) && v >= min;
  });
}

CLI::Validator ThreadCount(const std::string& option) {
  return IntegerIn(option, 0, MaxSolverThreads(),
                   "0: OpenMP default; at most 4 x the " + std::to_string(omp_get_num_procs()) + " processors");
}

CLI::Validator Positive(const std::string& option, const std::string& unit) {
  return Rule(option, "finite and > 0" + (unit.empty() ? "" : " (" + unit + ")"), [](const std::string& s) {
    double v = 0;
    return ParseDouble(s, &v) && std::isfinite(v) && v > 0;
  });
}

CLI::Validator NonNegative(const std::string& option) {
  return Rule(option, "finite and >= 0", [](const std::string& s) {
    double v = 0;
    return ParseDouble(s, &v) && std::isfinite(v) && v >= 0;
  });
}

CLI::Validator ZeroOrAtLeast(const std::string& option, double min) {
  char bound[32];
  std::snprintf(bound, sizeof(bound), "%g", min);
  return Rule(option, std::string("0 or finite and >= ") + bound, [min](const std::string& s) {
    double v = 0;
    return ParseDouble(s, &v) && (v == 0 || (std::isfinite(v) && v >= min));
  });
}

CLI::Validator Fraction(const std::string& option, bool include_one) {
  return Rule(option, include_one ? "in (0, 1]" : "in (0, 1)", [include_one](const std::string& s) {
    double v = 0;
    return ParseDouble(s, &v) && v > 0 && (include_one ? v <= 1 : v < 1);
  });
}

CLI::Validator OpenInterval(const std::string& option, double low, double high) {
  std::ostringstream range;
  range << "finite and in (" << low << ", " << high << ")";
  return Rule(option, range.str(), [low, high](const std::string& s) {
    double v = 0;
    return ParseDouble(s, &v) && std::isfinite(v) && v > low && v < high;
  });
}

}  // namespace diffpd::problems
