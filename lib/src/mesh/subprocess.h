// Running an external program (internal; used to call TetGen).
#pragma once

#include <string>
#include <vector>

namespace diffpd::internal {

// Full path of the first executable regular file named `program` in the
// directories of $PATH, or "" if there is none.
std::string FindOnPath(const std::string& program);

struct ProgramResult {
  // Exit status if the program exited normally, else -1.
  int exit_status = -1;
  // Signal number if it was killed by a signal, else 0.
  int signal = 0;
  // Everything it wrote to stdout and stderr, interleaved.
  std::string output;
};

// Runs `path` with `arguments` (argv[1..]; no shell involved) and waits for
// it, capturing its output in `log_path`, which is then read back. Throws
// std::runtime_error if the log cannot be created or the program cannot be
// started.
ProgramResult RunProgram(const std::string& path, const std::vector<std::string>& arguments,
                         const std::string& log_path);

}  // namespace diffpd::internal
