// The paper's application rows 1-11 (PROBLEMS.md), each built exactly as the
// fact sheet states at the paper's size (RowSize::kPaper) or reduced for
// tests (kSmall). Building a row reads its mesh and draws its random numbers
// but runs no simulation (see PaperRow::prepare).
#pragma once

#include <string>
#include <vector>

#include "paper/numpy_random.h"
#include "paper/paper_row.h"

namespace diffpd::problems {

PaperRow MakeCantileverRow(RowSize size);     // 1: timing only
PaperRow MakeRollingSphereRow(RowSize size);  // 2: timing only
PaperRow MakePlantRow(RowSize size);          // 3: material identification
PaperRow MakeBouncingBallRow(RowSize size);   // 4: material identification
PaperRow MakeBunnyRow(RowSize size);          // 5: initial-state optimisation
PaperRow MakeRoutingTendonRow(RowSize size);  // 6: static activation
PaperRow MakeTorusRow(RowSize size);          // 7: open-loop rolling
PaperRow MakeQuadrupedRow(RowSize size);      // 8: gait parameters
PaperRow MakeCowRow(RowSize size);            // 9: gait parameters
// 10 and 11, closed-loop swimming: the network's weights of starfish-control
// and shark-control (the original shark is not public), timed at the
// initial controller (not optimised here: `diffpd run` trains them).
PaperRow MakeStarfishRow(RowSize size);
PaperRow MakeSharkRow(RowSize size);

// "cantilever", "rolling-sphere", "plant", "bouncing-ball", "bunny",
// "routing-tendon", "torus", "quadruped", "cow", "starfish", "shark", in the
// Table's order.
std::vector<std::string> PaperRowNames();
// The row called `name`; throws InvalidInputError listing the valid names.
PaperRow MakePaperRow(const std::string& name, RowSize size);

// `count` vectors drawn uniformly within [lower, upper] (entry by entry, in
// order, as numpy.random.uniform(lower, upper)).
std::vector<VectorXd> UniformDraws(NumpyRandom* rng, const VectorXd& lower, const VectorXd& upper, int count);
// Sets a block's bounds variable by variable (lower, upper of its size).
void SetBlockBounds(solvers::ParameterBlock* block, const VectorXd& lower, const VectorXd& upper);

}  // namespace diffpd::problems
