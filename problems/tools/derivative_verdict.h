// The verdict on one directional derivative from central differences taken
// at several steps, each with an estimate of its noise.
//
// A central difference fd(e) = (L(+e) - L(-e)) / 2e errs by truncation,
// O(e^2) (O(e) where L is C1 but not C2), and by the noise of the two
// evaluations of L: rounding (declared as `noise`), and the residuals an
// iterative forward solve leaves. The latter's worst case (`bound`, e.g.
// from the achieved residuals) is far above what is seen, as the two
// evaluations' solves follow nearly the same path and their errors mostly
// cancel; so it is measured instead.
// From differences at steps e_0 > e_1 > ... (ratio r = e_k-1 / e_k, 10 in
// the checks), the uncertainty of fd(e_k) is the largest of
//   noise(e_k)                                the declared rounding;
//   |fd(e_k-1) - fd(e_k)| / (r^2 - 1)         its truncation error, measured
//                                             Richardson-style from the larger
//                                             step; / (r - 1) where the
//                                             distances of e_k-2, e_k-1 and
//                                             e_k shrink by less than r^1.5
//                                             (first-order truncation of a
//                                             loss that is C1 but not C2,
//                                             e.g. |u| u drag from rest)
//                                             (for e_0, which has none:
//                                             |fd(e_0) - fd(e_1)| plus the noise
//                                             of fd(e_1), measured from e_2, as
//                                             that noise can cancel the
//                                             truncation it is compared with);
//   |fd(e_k) - fd(e_k+1)| / r                 its noise, measured from the
//                                             smaller step's (noise ~ 1/e).
// The smallest step serves only to measure its neighbour's noise (with a
// single difference, that one is used with its declared noise). The check
// uses the step of least uncertainty; with
// scale = max(|fd|, |analytic|) there,
//
//   error = |fd - analytic| / scale,   floor = uncertainty / scale,
//
// and the verdict is
//   pass       error <= tolerance and floor <= tolerance;
//   fail       error > tolerance, error > 3 floor and error > bound (a
//              disagreement the differences resolve and the solves' worst
//              case cannot explain: a wrong derivative disagrees at every step);
//   unresolved otherwise: the differences cannot tell the derivative to the
//              tolerance (floor > tolerance); `reason` gives the floor.
// margin = tolerance / max(error, floor): how many times over the check
// would still pass; >= 1 for every pass.
//
// With three or more differences the same is done once more on their
// Richardson extrapolations x_k = fd(e_k) + (fd(e_k) - fd(e_k-1)) / d_k (d_k
// the divisor above, r^2 - 1 or r - 1), which cancel the leading truncation
// term; x_k's own truncation is |x_k-1 - x_k| / d_k, an over-estimate
// wherever x converges faster than fd. The extrapolated judgement is taken
// only where it passes with a larger margin than the differences' own and
// its error is at most 3x its floor (a larger error says the floor is not
// to be trusted: the loss is not smooth across the steps): it can confirm a
// derivative whose differences are truncation-limited, never fail one or
// leave it unresolved.
#pragma once

#include <string>
#include <vector>

namespace diffpd::problems {

enum class CheckVerdict { kPass, kFail, kUnresolved };
// "pass", "fail", "unresolved".
const char* ToString(CheckVerdict verdict);
// The worse of two verdicts: fail over unresolved over pass.
CheckVerdict Worse(CheckVerdict a, CheckVerdict b);
// `v` with two significant digits ("%.2g"), as the verdicts' reasons give
// errors, floors and tolerances.
std::string FormatTwoDigits(double v);

// One central difference: step e, value (L(+e) - L(-e)) / 2e, the rounding
// noise of the two evaluations and the worst-case error the forward's solves
// allow (both absolute, units of value; 0 when exact).
struct FiniteDifference {
  double step = 0;
  double value = 0;
  double noise = 0;
  double bound = 0;
};

struct DerivativeJudgement {
  CheckVerdict verdict = CheckVerdict::kUnresolved;
  double error = 0;           // relative, at the chosen step (see above)
  double floor = 0;           // relative uncertainty of the difference there (measured)
  double bound = 0;           // relative worst-case error from the solves there
  double step = 0;            // the chosen step
  double tolerance = 0;       // the relative tolerance judged against
  double margin = 0;          // tolerance / max(error, floor); infinite when both are 0
  std::string reason;         // empty for a pass; why it failed or is unresolved
  bool extrapolated = false;  // judged on the Richardson extrapolations (see above)
};

// `differences` in decreasing step order (at least one). tolerance > 0.
// extrapolate: also judge the Richardson extrapolations (see above).
// Throws std::invalid_argument on an empty list or a tolerance <= 0.
DerivativeJudgement JudgeDerivative(double analytic, const std::vector<FiniteDifference>& differences, double tolerance,
                                    bool extrapolate = true);

// The same for a vector-valued derivative (a Jacobian-vector product, a
// whole Jacobian flattened): every |.| above is a 2-norm. Throws
// std::invalid_argument also when a value's size differs from analytic's.
struct FiniteDifferenceVector {
  double step = 0;
  std::vector<double> value;
  double noise = 0;  // of the whole vector (2-norm), like FiniteDifference::noise
  double bound = 0;
};
DerivativeJudgement JudgeDerivative(const std::vector<double>& analytic,
                                    const std::vector<FiniteDifferenceVector>& differences, double tolerance,
                                    bool extrapolate = true);

}  // namespace diffpd::problems
