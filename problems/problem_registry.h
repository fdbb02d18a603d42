// Problems by name, for the command-line program and the tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "problem.h"

namespace diffpd::problems {

// All registered problems, in the order `diffpd list` prints them.
std::vector<std::unique_ptr<Problem>> AllProblems();
// The problem called `name`; throws InvalidInputError listing valid names.
std::unique_ptr<Problem> MakeProblem(const std::string& name);

}  // namespace diffpd::problems
