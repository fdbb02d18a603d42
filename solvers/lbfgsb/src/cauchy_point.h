// The generalized Cauchy point of L-BFGS-B (Byrd, Lu, Nocedal and Zhu 1995,
// section 4): the first local minimiser of the quadratic model
// m(z) = g^T (z - x) + 1/2 (z - x)^T B (z - x) along the projected gradient
// path x(t) = P(x - t g), found segment by segment between the breakpoints
// where variables reach their bounds, and the subspace minimisation of
// section 5 (direct primal method) over the variables free there.
#pragma once

#include <vector>

#include "diffpd/types.h"
#include "limited_memory_matrix.h"

namespace diffpd::solvers::lbfgsb_internal {

struct CauchyPoint {
  VectorXd x;             // the Cauchy point (within the bounds)
  VectorXd c;             // W^T (x_cauchy - x), 2k entries
  std::vector<int> free;  // variables not at a bound there, ascending
};

// x within [lower, upper]; g the gradient at x.
CauchyPoint GeneralizedCauchyPoint(const VectorXd& x, const VectorXd& g, const VectorXd& lower, const VectorXd& upper,
                                   const LimitedMemoryMatrix& b);

// The minimiser xbar of the model over the free variables of the Cauchy
// point (the others held there), projected onto the box when `project` and
// that gives a descent direction from x, else the subspace step truncated
// to the box. The Cauchy point itself with no pair or no free variable.
VectorXd SubspaceMinimum(const VectorXd& x, const VectorXd& g, const VectorXd& lower, const VectorXd& upper,
                         const CauchyPoint& cauchy, const LimitedMemoryMatrix& b, bool project);

}  // namespace diffpd::solvers::lbfgsb_internal
