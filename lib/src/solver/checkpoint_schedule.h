// The binomial checkpointing schedule (internal; checkpointed_rollout.h).
//
// Reversing l steps from a held state with s free checkpoint slots: if
// l = 1, differentiate the step; else advance m steps (BinomialSplit), keep
// the state there in a slot, reverse the l - m steps after it with s - 1
// slots, free the slot and reverse the first m steps with s slots. With
// beta(s, t) = (s + t)! / (s! t!) and t the least integer with beta(s, t)
// >= l (BinomialRepetitions), a split with beta(s, t - 2) < m <= beta(s, t - 1)
// and beta(s - 1, t - 1) < l - m <= beta(s - 1, t) (where both hold) is
// optimal: t l - beta(s + 1, t - 1) advances in all, every step advanced at
// most t times (Griewank 1992, "revolve"). The forward pass stores the states
// of the first descent (FirstDescentSteps), so the backward starts there.
#pragma once

#include <vector>

namespace diffpd::internal {

// t: the least t >= 0 with beta(slots, t) >= steps; steps >= 1, slots >= 1.
int BinomialRepetitions(int steps, int slots);
// m in [1, steps - 1] for steps >= 2 and slots >= 1 (see above; where no
// split meets both conditions, the nearest one that keeps every step within
// t advances).
int BinomialSplit(int steps, int slots);
// The steps at which the first descent from step 0 keeps states: ascending,
// at most `slots` of them, all in (0, steps).
std::vector<int> FirstDescentSteps(int steps, int slots);

}  // namespace diffpd::internal
