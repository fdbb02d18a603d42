#include "cauchy_point.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace diffpd::solvers::lbfgsb_internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

CauchyPoint GeneralizedCauchyPoint(const VectorXd& x, const VectorXd& g, const VectorXd& lower, const VectorXd& upper,
                                   const LimitedMemoryMatrix& b) {
  const int n = static_cast<int>(x.size());
  const int k2 = static_cast<int>(b.W().cols());
  const double theta = b.theta();
  const MatrixXd& w = b.W();
  const MatrixXd& m = b.M();

  CauchyPoint out;
  out.x = x;
  // Breakpoints t_i where x_i - t g_i meets its bound; d = -g on the
  // variables that can move (t_i > 0).
  VectorXd d = VectorXd::Zero(n);
  std::vector<bool> fixed(n, false);
  std::vector<std::pair<double, int>> breaks;
  for (int i = 0; i < n; ++i) {
    if (lower(i) == upper(i)) {
      fixed[i] = true;
      continue;
    }
    double t = kInf;
    if (g(i) < 0 && upper(i) < kInf)
      t = (x(i) - upper(i)) / g(i);
    else if (g(i) > 0 && lower(i) > -kInf)
      t = (x(i) - lower(i)) / g(i);
    if (t <= 0) {
      fixed[i] = true;  // at the bound the gradient pushes against
      continue;
    }
    d(i) = -g(i);
    if (t < kInf) breaks.push_back({t, i});
  }
  std::sort(breaks.begin(), breaks.end());

  VectorXd p = w.transpose() * d;                           // W^T d
  VectorXd c = VectorXd::Zero(k2);                          // W^T (x(t) - x)
  double f1 = -d.squaredNorm();                             // f' = g^T d
  double f2 = -theta * f1 - (k2 > 0 ? p.dot(m * p) : 0.0);  // f'' = d^T B d
  const double f2_initial = f2;
  double dt_min = f2 > 0 ? -f1 / f2 : (f1 < 0 ? kInf : 0.0);
  double t_old = 0;
  size_t next = 0;
  while (next < breaks.size() && f1 < 0) {
    const double t = breaks[next].first;
    const int bi = breaks[next].second;
    const double dt = t - t_old;
    if (dt_min < dt) break;
    ++next;
    // Variable bi reaches its bound at t.
    const double bound = d(bi) > 0 ? upper(bi) : lower(bi);
    out.x(bi) = bound;
    fixed[bi] = true;
    const double zb = bound - x(bi);
    const double gb = g(bi);
    c += dt * p;
    double wmc = 0, wmp = 0, wmw = 0;
    VectorXd wb;
    if (k2 > 0) {
      wb = w.row(bi).transpose();
      const VectorXd mwb = m * wb;
      wmc = mwb.dot(c);
      wmp = mwb.dot(p);
      wmw = mwb.dot(wb);
    }
    f1 += dt * f2 + gb * gb + theta * gb * zb - gb * wmc;
    f2 += -theta * gb * gb - 2 * gb * wmp - gb * gb * wmw;
    f2 = std::max(f2, std::numeric_limits<double>::epsilon() * f2_initial);
    if (k2 > 0) p += gb * wb;
    d(bi) = 0;
    dt_min = f2 > 0 ? -f1 / f2 : 0.0;
    t_old = t;
  }
  if (!std::isfinite(dt_min)) dt_min = 0;  // no curvature and no breakpoint: cannot happen with B > 0
  dt_min = std::max(dt_min, 0.0);
  t_old += dt_min;
  for (int i = 0; i < n; ++i)
    if (!fixed[i] && d(i) != 0) out.x(i) = std::clamp(x(i) + t_old * d(i), lower(i), upper(i));
  c += dt_min * p;
  out.c = c;
  for (int i = 0; i < n; ++i)
    if (!fixed[i]) out.free.push_back(i);
  return out;
}

VectorXd SubspaceMinimum(const VectorXd& x, const VectorXd& g, const VectorXd& lower, const VectorXd& upper,
                         const CauchyPoint& cauchy, const LimitedMemoryMatrix& b, bool project) {
  const int nf = static_cast<int>(cauchy.free.size());
  if (b.pairs() == 0 || nf == 0) return cauchy.x;
  const double theta = b.theta();
  const MatrixXd& w = b.W();
  const MatrixXd& m = b.M();
  const int k2 = static_cast<int>(w.cols());
  // Reduced gradient of the model at the Cauchy point: Z^T (g + theta (xc - x) - W M c).
  const VectorXd mc = m * cauchy.c;
  VectorXd r(nf);
  MatrixXd u(nf, k2);  // Z^T W
  for (int j = 0; j < nf; ++j) {
    const int i = cauchy.free[j];
    u.row(j) = w.row(i);
    r(j) = g(i) + theta * (cauchy.x(i) - x(i)) - w.row(i).dot(mc);
  }
  // du = -Bhat^-1 r, Bhat = theta I - U M U^T, by Sherman-Morrison-Woodbury:
  // Bhat^-1 = I / theta + U N^-1 M U^T / theta^2, N = I - M U^T U / theta.
  const MatrixXd n_matrix = MatrixXd::Identity(k2, k2) - m * (u.transpose() * u) / theta;
  const Eigen::PartialPivLU<MatrixXd> lu(n_matrix);
  const VectorXd v = lu.solve(m * (u.transpose() * r));
  const VectorXd du = -r / theta - u * v / (theta * theta);
  if (!du.allFinite()) return cauchy.x;

  VectorXd xbar = cauchy.x;
  if (project) {
    for (int j = 0; j < nf; ++j) {
      const int i = cauchy.free[j];
      xbar(i) = std::clamp(cauchy.x(i) + du(j), lower(i), upper(i));
    }
    if ((xbar - x).dot(g) < 0) return xbar;
  }
  // The largest alpha <= 1 with xc + alpha Z du inside the box.
  double alpha = 1;
  for (int j = 0; j < nf; ++j) {
    const int i = cauchy.free[j];
    if (du(j) > 0 && upper(i) < kInf)
      alpha = std::min(alpha, (upper(i) - cauchy.x(i)) / du(j));
    else if (du(j) < 0 && lower(i) > -kInf)
      alpha = std::min(alpha, (lower(i) - cauchy.x(i)) / du(j));
  }
  alpha = std::max(alpha, 0.0);
  xbar = cauchy.x;
  for (int j = 0; j < nf; ++j) {
    const int i = cauchy.free[j];
    xbar(i) = std::clamp(cauchy.x(i) + alpha * du(j), lower(i), upper(i));
  }
  return xbar;
}

}  // namespace diffpd::solvers::lbfgsb_internal
