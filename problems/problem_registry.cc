#include "problem_registry.h"

#include "cantilever.h"
#include "diffpd/error.h"

namespace diffpd::problems {

std::vector<std::unique_ptr<Problem>> AllProblems() {
  std::vector<std::unique_ptr<Problem>> all;
  all.push_back(std::make_unique<Cantilever>());
  all.push_back(std::make_unique<FallingCube>());
  return all;
}

std::unique_ptr<Problem> MakeProblem(const std::string& name) {
  std::string valid;
  for (auto& p : AllProblems()) {
    if (p->name() == name) return std::move(p);
    valid += (valid.empty() ? "" : ", ") + p->name();
  }
  throw InvalidInputError("unknown problem '" + name + "': valid problems are " + valid);
}

}  // namespace diffpd::problems
