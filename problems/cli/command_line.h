// The diffpd program's command line, callable in-process (main.cc and the
// tests): parses argv, runs the subcommand and returns the exit status.
#pragma once

#include <string>
#include <vector>

namespace diffpd::problems {

// argv[0] is the program name. Errors go to stderr: a command-line error as
// CLI11 reports it (its exit status, e.g. 105 for a failed conversion),
// "diffpd: invalid input: <message>" (status 2) for InvalidInputError,
// including out-of-range option values (option_checks.h), "diffpd: solver
// failed (<status>): <message>" (3) for SolverError, "diffpd: error:
// <message>" (1) for any other exception. Otherwise the subcommand's status.
int RunCommandLine(const std::vector<std::string>& argv);

}  // namespace diffpd::problems
