#include "paper/paper_rows.h"

#include "diffpd/error.h"

namespace diffpd::problems {

std::vector<std::string> PaperRowNames() {
  return {"cantilever", "rolling-sphere", "plant", "bouncing-ball", "bunny", "routing-tendon",
          "torus",      "quadruped",      "cow",   "starfish",      "shark"};
}

PaperRow MakePaperRow(const std::string& name, RowSize size) {
  if (name == "cantilever") return MakeCantileverRow(size);
  if (name == "rolling-sphere") return MakeRollingSphereRow(size);
  if (name == "plant") return MakePlantRow(size);
  if (name == "bouncing-ball") return MakeBouncingBallRow(size);
  if (name == "bunny") return MakeBunnyRow(size);
  if (name == "routing-tendon") return MakeRoutingTendonRow(size);
  if (name == "torus") return MakeTorusRow(size);
  if (name == "quadruped") return MakeQuadrupedRow(size);
  if (name == "cow") return MakeCowRow(size);
  if (name == "starfish") return MakeStarfishRow(size);
  if (name == "shark") return MakeSharkRow(size);
  std::string valid;
  for (const std::string& n : PaperRowNames()) valid += (valid.empty() ? "" : ", ") + n;
  throw InvalidInputError("unknown table row '" + name + "': valid rows are " + valid);
}

std::vector<VectorXd> UniformDraws(NumpyRandom* rng, const VectorXd& lower, const VectorXd& upper, int count) {
  std::vector<VectorXd> draws;
  for (int i = 0; i < count; ++i) draws.push_back(rng->Uniform(lower, upper));
  return draws;
}

void SetBlockBounds(solvers::ParameterBlock* block, const VectorXd& lower, const VectorXd& upper) {
  for (int j = 0; j < block->size(); ++j) block->SetBounds(j, 1, lower(j), upper(j));
}

}  // namespace diffpd::problems
