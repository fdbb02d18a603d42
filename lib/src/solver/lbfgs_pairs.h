// L-BFGS curvature pairs and the two loops of its recursion (internal): the
// memory of PD-LBFGS's forward steps and of the adjoint's L-BFGS.
//
// H g for the L-BFGS inverse Hessian H with initial H0 is
//   q = g;  FirstLoop(&q, &alpha);  r = H0 q;  SecondLoop(alpha, &r);  // r = H g
// The pairs live in a ring of preallocated vectors (no allocation per
// iteration). The loops read every stored vector once each (20 pairs of
// 8 019-vectors: 5 MB per recursion, from the L3 cache: ~0.17 ms on the
// cantilever). Tried and not kept: the update of pair j and the dot product
// of pair j -/+ 1 in one pass over slices of the vectors, on 2 threads:
// 0.13-0.19 ms on 2 threads but 0.21-0.26 ms on one (Eigen's whole-vector
// passes ran faster than interleaved slices); pairs stored as floats (slower
// at this size; docs/benchmarks.md).
#pragma once

#include <vector>

#include "diffpd/types.h"

namespace diffpd::internal {

class LbfgsPairs {
 public:
  // At most `capacity` (>= 1) pairs of n-vectors.
  LbfgsPairs(int capacity, Eigen::Index n);

  int size() const { return size_; }
  int capacity() const { return capacity_; }
  Eigen::Index dimension() const { return n_; }
  void Clear() { size_ = 0; }
  // Appends (s, y) with rho = 1 / (s^T y), dropping the oldest pair when full.
  void Push(const VectorXd& s, const VectorXd& y, double rho);

  // For j from newest to oldest: alpha_j = rho_j s_j^T q, q -= alpha_j y_j.
  // alpha (resized to size()) is indexed oldest first.
  void FirstLoop(VectorXd* q, std::vector<double>* alpha) const;
  // For j from oldest to newest: r += (alpha_j - rho_j y_j^T r) s_j.
  void SecondLoop(const std::vector<double>& alpha, VectorXd* r) const;

 private:
  // Pair i (0 = oldest) sits in slot (head_ + i) % capacity.
  int Slot(int i) const { return (head_ + i) % capacity_; }

  int capacity_;
  Eigen::Index n_;
  std::vector<VectorXd> s_, y_;
  std::vector<double> rho_;
  int head_ = 0;
  int size_ = 0;
};

}  // namespace diffpd::internal
