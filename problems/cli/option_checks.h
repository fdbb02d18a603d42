// Range checks of the diffpd program's numeric options, as CLI11 validators
// that refuse a value with the project's message and InvalidInputError
// (exit status 2), e.g.
//   "--dt = 0 is invalid: must be finite and > 0 (s)",
//   "--steps = -5 is invalid: must be an integer >= 1",
// instead of CLI11's "Value 0 not in range 0.000000 to 1.797e308" or, for
// options whose default is a sentinel (-1: the problem's own), silently
// running with the default. The value is quoted as given. A validator runs
// only on a value given on the command line, never on a default.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace diffpd::problems {

// An integer in [min, max]; `note` is appended in parentheses if not empty:
// "--verbosity = 3 is invalid: must be an integer in [0, 2]".
CLI::Validator IntegerIn(const std::string& option, long min, long max, const std::string& note = "");
// An integer >= min: "--steps = 0 is invalid: must be an integer >= 1".
CLI::Validator IntegerAtLeast(const std::string& option, long min);
// A thread count in [0, MaxSolverThreads()] (solver_options.h): "--threads =
// 99999 is invalid: must be an integer in [0, 8] (0: OpenMP default; at most
// 4 x the 2 processors)".
CLI::Validator ThreadCount(const std::string& option);
// A finite number > 0, `unit` in parentheses if not empty: "--dt = nan is
// invalid: must be finite and > 0 (s)".
CLI::Validator Positive(const std::string& option, const std::string& unit = "");
// A finite number >= 0: "--energy-tol = -1 is invalid: must be finite and >= 0".
CLI::Validator NonNegative(const std::string& option);
// 0 or a finite number >= min: "--early-stop = 0.5 is invalid: must be 0 or
// finite and >= 1".
CLI::Validator ZeroOrAtLeast(const std::string& option, double min);
// A number in (0, 1), or (0, 1] with include_one: "--rtol = 0 is invalid:
// must be in (0, 1)".
CLI::Validator Fraction(const std::string& option, bool include_one = false);
// A finite number in the open interval (low, high): "--nu = 0.7 is invalid:
// must be finite and in (-1, 0.5)".
CLI::Validator OpenInterval(const std::string& option, double low, double high);

}  // namespace diffpd::problems
