// diffpd: command-line front end of the DiffPD library (cli/command_line.h).
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "tools/openmp_waits.h"

int main(int argc, char** argv) {
  diffpd::problems::UseShortOpenMpWaits(argv);
  return diffpd::problems::RunCommandLine(std::vector<std::string>(argv, argv + argc));
}
