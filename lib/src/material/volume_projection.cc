// The closest point d to sigma on {d : d_0 d_1 d_2 = 1} (Euclidean norm),
// and its derivative. This is the singular-value part of the PD volume
// projection Proj_{det=1}(F) = U diag(d) V^T.
//
// Structure of the problem (stationarity d_i (d_i - sigma_i) = mu, i = 0..2):
//  - Sign patterns: since sigma_0 >= sigma_1 >= |sigma_2|, flipping two
//    signs of d towards sigma's signs never increases the distance, so the
//    minimiser is either all positive, or (only when sigma_2 < 0) of signs
//    (+, -, -), i.e. the all-positive problem for s = (sigma_0, -sigma_1, -sigma_2).
//  - All-positive problem for a target s: each d_i is a root of
//    d^2 - s_i d - mu = 0. At a minimiser at most one d_i is the smaller root
//    ("shrinking branch", d_i < s_i / 2; the Lagrangian Hessian is negative
//    there), and only for the smallest s_k (swapping two entries otherwise
//    shortens the distance). Parametrising by t = d_k, mu(t) = t (t - s_k)
//    and d_j = D(s_j, mu), the larger root, for j != k, every candidate is a
//    root of h(t) = log(t d_i d_j) on (0, inf):
//      * t >= s_k / 2: h is strictly increasing: at most one root, found by a
//        safeguarded Newton iteration (the common case, ~3 iterations from
//        t = s_k / cbrt(prod s));
//      * 0 < t < s_k / 3 (s_k > 0 only): h is strictly increasing too
//        (t h' >= (s_k - 3t) / (s_k - t) > 0);
//      * s_k / 3 <= t < s_k / 2: h may be non-monotone; scanned on a grid.
//    These shrinking-branch roots exist only if t d_i d_j >= 1 somewhere,
//    which needs prod(s) >= 2 (t <= s_k / 2 and d_j <= s_j there), so the
//    extra work is skipped for all but large volume expansions.
//  The candidate closest to sigma wins.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "diffpd/error.h"
#include "material/projections.h"
#include "material/simd_dispatch.h"

namespace diffpd::internal {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kMaxIterations = 200;
constexpr int kScanIntervals = 8;

// Larger root D >= s/2 of D^2 - s D - mu = 0 (needs s^2 + 4 mu >= 0, and
// mu >= 0 when s < 0), without cancellation; r = 2 D - s = sqrt(s^2 + 4 mu).
struct Root {
  double d;
  double r;
};
inline Root LargerRoot(double s, double mu) {
  const double r = std::sqrt(std::max(s * s + 4.0 * mu, 0.0));
  return {s >= 0.0 ? 0.5 * (s + r) : 2.0 * mu / (r - s), r};
}

// A point of the stationary path of the all-positive problem for target s,
// parametrised by t = d_k (k: index of the smallest entry of s).
struct PathPoint {
  Vec3 d = Vec3::Ones();
  double h = 0;   // log(d_0 d_1 d_2)
  double dh = 0;  // dh / dt
  double mu = 0;  // multiplier: d_i (d_i - s_i) = mu
};

class StationaryPath {
 public:
  // k: the last index of the smallest entry (ties: the last one shrinks).
  explicit StationaryPath(const Vec3& s) : s_(s) {
    for (int j = 1; j < 3; ++j) {
      if (s(j) <= s(k_)) k_ = j;
    }
  }
  int k() const { return k_; }
  double sk() const { return s_(k_); }
  const Vec3& s() const { return s_; }

  PathPoint Evaluate(double t) const {
    PathPoint p;
    p.mu = t * (t - s_(k_));
    const double dmu = 2.0 * t - s_(k_);
    p.d(k_) = t;
    double product = t;
    p.dh = 1.0 / t;
    for (int j = 0; j < 3; ++j) {
      if (j == k_) continue;
      const Root root = LargerRoot(s_(j), p.mu);
      p.d(j) = root.d;
      product *= root.d;
      if (dmu != 0.0) p.dh += dmu / (root.r * root.d);
    }
    p.h = std::log(product);
    return p;
  }

 private:
  Vec3 s_;
  int k_ = 0;
};

// Keeps the candidate closest to the target s (no allocation: this runs at
// every quadrature point in every PD iteration).
class ClosestRoot {
 public:
  explicit ClosestRoot(const Vec3& s) : s_(s) {}
  void push_back(const PathPoint& p) {
    const double distance = (p.d - s_).squaredNorm();
    if (distance < distance_) {
      distance_ = distance;
      best_ = p;
    }
  }
  double distance() const { return distance_; }
  const PathPoint& best() const { return best_; }

 private:
  Vec3 s_;
  double distance_ = std::numeric_limits<double>::infinity();
  PathPoint best_;
};

// Midpoint for bisection of a positive bracket: geometric when wide.
inline double Midpoint(double lo, double hi) { return hi > 4.0 * lo ? std::sqrt(lo * hi) : 0.5 * (lo + hi); }

// Root of the path's h in [lo, hi] (0 < lo <= hi) where h changes sign,
// increasing (direction = +1) or decreasing (direction = -1) through it.
// Newton steps, bisection whenever a step leaves the bracket.
PathPoint FindRoot(const StationaryPath& path, double lo, double hi, double direction, double guess) {
  double t = std::clamp(guess, lo, hi);
  PathPoint p = path.Evaluate(t);
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    const double f = direction * p.h;
    if (std::abs(f) <= 4.0 * kEps) break;
    if (f < 0.0)
      lo = t;
    else
      hi = t;
    if (hi - lo <= 4.0 * kEps * hi) break;
    double next = t - p.h / p.dh;
    if (!(next > lo && next < hi)) next = Midpoint(lo, hi);
    if (std::abs(next - t) <= 4.0 * kEps * t) break;
    t = next;
    p = path.Evaluate(t);
  }
  return p;
}

// Appends the roots of h on the increasing part t >= max(s_k / 2, 0).
void GrowingBranchRoots(const StationaryPath& path, ClosestRoot* roots) {
  const Vec3& s = path.s();
  const double sk = path.sk();
  double lo;
  if (sk > 0.0) {
    lo = 0.5 * sk;
    // At t = s_k/2, d_j <= s_j, so t d_i d_j <= prod(s)/2: only a large
    // expansion (prod(s) > 2) can put h(lo) above 0, and then every
    // t >= s_k/2 has t d_i d_j > 1 (no root on this branch).
    if (!(s.prod() <= 2.0) && path.Evaluate(lo).h > 0.0) return;
  } else {
    // For t <= 1: mu <= 1 + |s_k|, d_j <= max(s_j, 0) + sqrt(1 + |s_k|).
    const double bound = std::sqrt(1.0 - sk);
    double c = 1.0;
    for (int j = 0; j < 3; ++j) {
      if (j != path.k()) c *= std::max(s(j), 0.0) + bound;
    }
    lo = 1.0 / c;  // h(lo) <= 0
  }
  const double hi = std::max(lo, 1.0);  // d_j >= t there, so h(1) >= 0
  const double product = std::abs(s.prod());
  const double guess = product > 0.0 && std::isfinite(product) ? std::abs(sk) / std::cbrt(product) : Midpoint(lo, hi);
  roots->push_back(FindRoot(path, lo, hi, 1.0, guess));
}

// Appends the roots of h on 0 < t < s_k / 2 (the shrinking branch of d_k).
void ShrinkingBranchRoots(const StationaryPath& path, ClosestRoot* roots) {
  const Vec3& s = path.s();
  const double sk = path.sk();
  if (!(sk > 0.0) || !(s.prod() >= 2.0)) return;
  // (0, s_k/3]: h increasing, h(t) <= log(t s_i s_j).
  const double third = sk / 3.0;
  const PathPoint at_third = path.Evaluate(third);
  if (at_third.h >= 0.0) {
    const double lo = std::min(0.5 * sk / s.prod(), third);
    roots->push_back(FindRoot(path, lo, third, 1.0, 0.5 * (lo + third)));
  }
  // [s_k/3, s_k/2): grid; within each interval h is assumed to have at most
  // one critical point, located by bisection on h' when the signs of h' at
  // the ends say it may reach zero.
  PathPoint a = at_third;
  for (int n = 1; n <= kScanIntervals; ++n) {
    const double tb = third + (0.5 * sk - third) * n / kScanIntervals;
    const PathPoint b = path.Evaluate(tb);
    const double ta = a.d(path.k());
    if ((a.h < 0.0) != (b.h < 0.0)) {
      roots->push_back(FindRoot(path, ta, tb, a.h < 0.0 ? 1.0 : -1.0, 0.5 * (ta + tb)));
    } else if ((a.dh > 0.0) != (b.dh > 0.0) && (a.dh > 0.0) == (a.h < 0.0)) {
      double lo = ta, hi = tb;  // h' changes sign between lo and hi
      for (int iteration = 0; iteration < 60 && hi - lo > 4.0 * kEps * hi; ++iteration) {
        const double mid = 0.5 * (lo + hi);
        if ((path.Evaluate(mid).dh > 0.0) == (a.dh > 0.0))
          lo = mid;
        else
          hi = mid;
      }
      const PathPoint extremum = path.Evaluate(0.5 * (lo + hi));
      if ((extremum.h < 0.0) != (a.h < 0.0)) {
        const double te = extremum.d(path.k());
        const double direction = a.h < 0.0 ? 1.0 : -1.0;
        roots->push_back(FindRoot(path, ta, te, direction, 0.5 * (ta + te)));
        roots->push_back(FindRoot(path, te, tb, -direction, 0.5 * (te + tb)));
      }
    }
    a = b;
  }
}

// Closest candidate for the all-positive problem with target s; returns the
// squared distance (infinity if no candidate was found).
double SolvePositive(const Vec3& s, VolumeProjection* best) {
  const StationaryPath path(s);
  ClosestRoot roots(s);
  GrowingBranchRoots(path, &roots);
  ShrinkingBranchRoots(path, &roots);
  if (roots.distance() < std::numeric_limits<double>::infinity()) {
    best->d = roots.best().d;
    best->multiplier = roots.best().mu;
  }
  return roots.distance();
}

// Fast path for the common case 0 < sigma_2 (so all positive) and
// prod(sigma) < 2, where the minimiser is the unique root of the growing
// branch (no shrinking-branch candidate exists, see above, and no sign flip
// is considered): d_i = D(sigma_i, mu) for all i, with mu the root of
//   f(mu) = prod_i D(sigma_i, mu) - 1,  r_i = sqrt(sigma_i^2 + 4 mu),
//   f' = P sum_i a_i,  f'' = P ((sum_i a_i)^2 - sum_i (1 + 2 D_i / r_i) a_i^2),
//   a_i = 1 / (D_i r_i),  P = prod_i D_i,
// on mu > -sigma_2^2 / 4 (f is increasing there). Halley's iteration from
// the first-order guess mu_0 = -log(prod sigma) / sum_i sigma_i^-2 (with
// log p ~ 2 (p - 1) / (p + 1)) converges cubically: two or three evaluations
// of f for the strains of a typical PD iteration, against ~4 plus a cube
// root and logarithms for the general path; no logarithm, so the batched
// form below vectorises. The iteration stops when |P - 1| <= 4 eps.
constexpr int kMaxHalleySteps = 8;
// sigma_2 > 0, all finite and prod(sigma) < 2, branch-free (the lane loop
// below vectorises with it): a non-finite entry makes the sum's difference
// with itself NaN.
DIFFPD_SIMD_INLINE bool FastPathApplies(double s0, double s1, double s2) {
  const double sum = s0 + s1 + s2;
  return (s2 > 0.0) & (s0 * s1 * s2 < 2.0) & (sum - sum == 0.0);
}
DIFFPD_SIMD_INLINE double FirstOrderMultiplier(double s0, double s1, double s2) {
  const double p = s0 * s1 * s2;
  const double inv0 = 1.0 / s0, inv1 = 1.0 / s1, inv2 = 1.0 / s2;
  return -2.0 * (p - 1.0) / ((p + 1.0) * (inv0 * inv0 + inv1 * inv1 + inv2 * inv2));
}
// One Halley evaluation at mu: d_i, the residual f = P - 1 and the next mu
// (scalar arguments, so that the lane loop calling it vectorises).
DIFFPD_SIMD_INLINE void HalleyTerm(double s, double mu, double* d, double* a, double* c) {
  const double r = std::sqrt(s * s + 4.0 * mu);
  *d = 0.5 * (s + r);
  *a = 1.0 / (*d * r);
  *c = (1.0 + 2.0 * *d / r) * *a * *a;
}
DIFFPD_SIMD_INLINE double HalleyStep(double s0, double s1, double s2, double mu, double* d0, double* d1, double* d2,
                                     double* residual) {
  double a0, a1, a2, c0, c1, c2;
  HalleyTerm(s0, mu, d0, &a0, &c0);
  HalleyTerm(s1, mu, d1, &a1, &c1);
  HalleyTerm(s2, mu, d2, &a2, &c2);
  const double product = *d0 * *d1 * *d2;
  const double sum = a0 + a1 + a2;
  const double curvature = c0 + c1 + c2;
  const double f = product - 1.0;
  const double df = product * sum;
  const double d2f = product * (sum * sum - curvature);
  *residual = f;
  return mu - 2.0 * f * df / (2.0 * df * df - f * d2f);
}

bool GrowingRootByMultiplier(const Vec3& s, VolumeProjection* out) {
  double mu = FirstOrderMultiplier(s(0), s(1), s(2));
  const double mu_floor = -0.25 * s(2) * s(2);
  for (int iteration = 0; iteration <= kMaxHalleySteps; ++iteration) {
    if (!(mu > mu_floor)) return false;
    double d[3], residual;
    const double next = HalleyStep(s(0), s(1), s(2), mu, &d[0], &d[1], &d[2], &residual);
    if (std::abs(residual) <= 4.0 * kEps) {
      out->d = Vec3(d[0], d[1], d[2]);
      out->multiplier = mu;
      return true;
    }
    mu = next;
  }
  return false;
}

}  // namespace

// The fast path for kVolumeBatch targets at once, lane by lane (OpenMP SIMD),
// one clone per vector width (simd_dispatch.h).
DIFFPD_SIMD_CLONES
void ProjectVolumeLanes(VolumeLanes& b) {
  // done: -1 outside the common case (FastPathApplies; never iterated),
  // 0 pending, 1 converged.
#pragma omp simd
  for (int l = 0; l < kVolumeBatch; ++l) {
    const double s0 = b.s[0][l], s1 = b.s[1][l], s2 = b.s[2][l];
    const bool applies = FastPathApplies(s0, s1, s2);
    b.mu[l] = applies ? FirstOrderMultiplier(s0, s1, s2) : 0.0;
    b.done[l] = applies ? 0.0 : -1.0;
    for (int i = 0; i < 3; ++i) b.d[i][l] = 1.0;
  }
  for (int iteration = 0; iteration <= kMaxHalleySteps; ++iteration) {
    int pending = 0;
    // Branch-free body (bitwise & on the tests, selects for the updates) so
    // that the lanes vectorise.
#pragma omp simd reduction(+ : pending)
    for (int l = 0; l < kVolumeBatch; ++l) {
      const double s0 = b.s[0][l], s1 = b.s[1][l], s2 = b.s[2][l];
      const double mu = b.mu[l];
      const bool active = (b.done[l] == 0.0) & (mu > -0.25 * s2 * s2);
      const double m = active ? mu : 0.0;
      double d0, d1, d2, residual;
      const double next = HalleyStep(s0, s1, s2, m, &d0, &d1, &d2, &residual);
      const bool converged = active & (std::abs(residual) <= 4.0 * kEps);
      const bool go_on = active & !converged;
      b.d[0][l] = converged ? d0 : b.d[0][l];
      b.d[1][l] = converged ? d1 : b.d[1][l];
      b.d[2][l] = converged ? d2 : b.d[2][l];
      b.done[l] = converged ? 1.0 : b.done[l];
      b.mu[l] = go_on ? next : mu;
      pending += go_on ? 1 : 0;
    }
    if (pending == 0) break;
  }
#pragma omp simd
  for (int l = 0; l < kVolumeBatch; ++l) b.done[l] = b.done[l] > 0.0 ? 1.0 : 0.0;
}

VolumeProjection ProjectSingularValuesToUnitDeterminant(const Vec3& sigma) {
  if (!sigma.allFinite()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {Vec3::Constant(nan), nan};
  }
  VolumeProjection best{Vec3::Ones(), 0.0};
  if (FastPathApplies(sigma(0), sigma(1), sigma(2)) && GrowingRootByMultiplier(sigma, &best)) return best;
  const double distance = SolvePositive(sigma, &best);
  if (sigma(2) < 0.0) {
    // Signs (+, -, -): d = flip .* d', d' the all-positive solution for
    // s = flip .* sigma; the multiplier is unchanged (d_i - sigma_i = mu / d_i).
    const Vec3 flip(1.0, -1.0, -1.0);
    VolumeProjection flipped{Vec3::Ones(), 0.0};
    if (SolvePositive(flip.cwiseProduct(sigma), &flipped) < distance) {
      best.d = flip.cwiseProduct(flipped.d);
      best.multiplier = flipped.multiplier;
    }
  }
  return best;
}

Mat3 UnitDeterminantProjectionJacobian(const Vec3& sigma, const VolumeProjection& projection) {
  // Differentiating d_i - sigma_i - mu / d_i = 0 and sum_i log|d_i| = 0:
  //   [H    -g] [dd ]   [dsigma]
  //   [g^T   0] [dmu] = [  0   ],  H = diag(1 + mu / d_i^2), g = 1 / d.
  // With w = H^-1 g: dd/dsigma = H^-1 - w w^T / (g^T w). H is singular only
  // where the smallest d_i switches solution branch (d_i = sigma_i / 2); there
  // the bordered system is solved as it stands.
  const Vec3& d = projection.d;
  const double mu = projection.multiplier;
  const Vec3 g = d.cwiseInverse();
  const Vec3 h = Vec3::Ones() + mu * g.cwiseProduct(g);
  if (h.cwiseAbs().minCoeff() > 1e-4) {  // cancellation error <= ~eps / 1e-4
    const Vec3 w = g.cwiseQuotient(h);
    Mat3 jacobian = -(w * w.transpose()) / g.dot(w);
    jacobian.diagonal() += h.cwiseInverse();
    return jacobian;
  }
  Eigen::Matrix4d kkt = Eigen::Matrix4d::Zero();
  kkt.topLeftCorner<3, 3>() = h.asDiagonal();
  kkt.topRightCorner<3, 1>() = -g;
  kkt.bottomLeftCorner<1, 3>() = g.transpose();
  Eigen::Matrix<double, 4, 3> rhs = Eigen::Matrix<double, 4, 3>::Zero();
  rhs.topRows<3>().setIdentity();
  return kkt.fullPivLu().solve(rhs).topRows<3>();
}

IsotropicDifferentialCoefficients UnitDeterminantProjectionCoefficients(const Vec3& sigma,
                                                                        const VolumeProjection& projection) {
  const Vec3& d = projection.d;
  const Mat3 jacobian = UnitDeterminantProjectionJacobian(sigma, projection);
  IsotropicDifferentialCoefficients c = DividedDifferenceCoefficients(sigma, d, jacobian);
  for (int k = 0; k < 3; ++k) {
    const int i = kPairFirst[k], j = kPairSecond[k];
    // Branch of d_i: larger root when (2 d_i - sigma_i) sign(d_i) >= 0.
    const bool same_sign = (d(i) > 0.0) == (d(j) > 0.0);
    const bool larger_i = (2.0 * d(i) - sigma(i)) * d(i) >= 0.0;
    const bool larger_j = (2.0 * d(j) - sigma(j)) * d(j) >= 0.0;
    if (same_sign && larger_i == larger_j) continue;
    const double threshold = kRepeatedSingularValueTolerance * std::max(std::abs(sigma(i)), std::abs(sigma(j)));
    const double denominator = std::max({sigma(i) - sigma(j), threshold, DenominatorFloor(sigma)});
    c.symmetric(k) = (d(i) - d(j)) / denominator;
  }
  return c;
}

void ProjectSingularValuesToUnitDeterminantBatch(int count, const Vec3* sigma, VolumeProjection* out) {
  DIFFPD_CHECK(count >= 0 && count <= kVolumeBatch, "ProjectSingularValuesToUnitDeterminantBatch: count = " << count);
  VolumeLanes b;
  for (int l = 0; l < kVolumeBatch; ++l)
    for (int i = 0; i < 3; ++i) b.s[i][l] = l < count ? sigma[l](i) : 1.0;  // idle lanes: sigma = (1, 1, 1)
  ProjectVolumeLanes(b);
  for (int l = 0; l < count; ++l) {
    if (b.done[l] != 0.0) {
      out[l].d = Vec3(b.d[0][l], b.d[1][l], b.d[2][l]);
      out[l].multiplier = b.mu[l];
    } else {
      out[l] = ProjectSingularValuesToUnitDeterminant(sigma[l]);
    }
  }
}

}  // namespace diffpd::internal
