#include "solver/checkpoint_schedule.h"

#include <algorithm>
#include <cstdint>

namespace diffpd::internal {
namespace {

// beta(s, t) = (s + t)! / (s! t!) (0 for t < 0), or `cap` if that is smaller.
int64_t Beta(int s, int t, int64_t cap) {
  if (t < 0) return 0;
  int64_t b = 1;
  for (int j = 1; j <= t && b < cap; ++j) b = b * (s + j) / j;  // exact: b * (s + j) is divisible by j
  return std::min(b, cap);
}

}  // namespace

int BinomialRepetitions(int steps, int slots) {
  int t = 0;
  int64_t b = 1;  // beta(slots, t)
  while (b < steps) {
    ++t;
    b = b * (slots + t) / t;
  }
  return t;
}

int BinomialSplit(int steps, int slots) {
  const int t = BinomialRepetitions(steps, slots);
  const int64_t l = steps;
  // Optimal where the first part needs t - 1 repetitions and the second t:
  // beta(s, t - 2) < m <= beta(s, t - 1), beta(s - 1, t - 1) < l - m <= beta(s - 1, t).
  int64_t m = std::min(Beta(slots, t - 1, l), l - Beta(slots - 1, t - 1, l) - 1);
  m = std::max(m, l - Beta(slots - 1, t, l));
  return static_cast<int>(std::clamp<int64_t>(m, 1, l - 1));
}

std::vector<int> FirstDescentSteps(int steps, int slots) {
  std::vector<int> out;
  int a = 0, l = steps, s = slots;
  while (l >= 2 && s >= 1) {
    const int m = BinomialSplit(l, s);
    a += m;
    l -= m;
    --s;
    out.push_back(a);
  }
  return out;
}

}  // namespace diffpd::internal
