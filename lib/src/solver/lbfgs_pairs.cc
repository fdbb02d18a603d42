#include "solver/lbfgs_pairs.h"

#include "diffpd/error.h"

namespace diffpd::internal {

LbfgsPairs::LbfgsPairs(int capacity, Eigen::Index n)
    : capacity_(capacity), n_(n), s_(capacity, VectorXd(n)), y_(capacity, VectorXd(n)), rho_(capacity, 0.0) {
  DIFFPD_CHECK(capacity >= 1 && n >= 0, "LbfgsPairs: capacity " << capacity << ", size " << n);
}

void LbfgsPairs::Push(const VectorXd& s, const VectorXd& y, double rho) {
  DIFFPD_CHECK(s.size() == n_ && y.size() == n_, "LbfgsPairs::Push: sizes " << s.size() << ", " << y.size());
  int slot;
  if (size_ == capacity_) {
    slot = head_;
    head_ = (head_ + 1) % capacity_;
  } else {
    slot = Slot(size_++);
  }
  s_[slot] = s;
  y_[slot] = y;
  rho_[slot] = rho;
}

void LbfgsPairs::FirstLoop(VectorXd* q, std::vector<double>* alpha) const {
  DIFFPD_CHECK(q->size() == n_, "LbfgsPairs::FirstLoop: size " << q->size());
  alpha->assign(size_, 0.0);
  for (int j = size_ - 1; j >= 0; --j) {
    const int slot = Slot(j);
    (*alpha)[j] = rho_[slot] * s_[slot].dot(*q);
    *q -= (*alpha)[j] * y_[slot];
  }
}

void LbfgsPairs::SecondLoop(const std::vector<double>& alpha, VectorXd* r) const {
  DIFFPD_CHECK(r->size() == n_ && static_cast<int>(alpha.size()) == size_,
               "LbfgsPairs::SecondLoop: size " << r->size() << ", " << alpha.size() << " coefficients");
  for (int j = 0; j < size_; ++j) {
    const int slot = Slot(j);
    const double beta = rho_[slot] * y_[slot].dot(*r);
    *r += (alpha[j] - beta) * s_[slot];
  }
}

}  // namespace diffpd::internal
