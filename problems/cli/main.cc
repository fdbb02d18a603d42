// diffpd: command-line front end of the DiffPD library (cli/command_line.h).
#include <string>
#include <vector>

#include "cli/command_line.h"

int main(int argc, char** argv) {
  return diffpd::problems::RunCommandLine(std::vector<std::string>(argv, argv + argc));
}
