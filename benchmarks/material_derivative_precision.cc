// How precisely the material derivatives of one implicit step are known at
// the stiff, nearly incompressible extreme: a free hexahedral cell (0.1 m,
// 1 kg, pd-corotated + pd-volume, 2 x 2 x 2 Gauss points, lumped mass,
// gravity) released squashed to 0.9 of its height, one implicit Euler step
// of h under random nodal forces of 0.1 x a node's weight, loss
// L = cx . x_1 + cv . v_1 (random cx, cv; one draw per seed).
//
// The library's reverse mode (Backward) and forward mode (Tangents) give
// dL/dnu and dL/dE in double precision (newton-cholesky and pd-lbfgs). The
// same step written out independently in quadruple precision (__float128:
// the closest rotation and the closest unit-determinant matrix from an
// eigen-decomposition of F^T F, the step solved by Newton's method with a
// difference Hessian) gives the exact derivative by the implicit function
// theorem, confirmed by central differences of the quadruple-precision loss
// (both printed). The quadruple-precision derivative is also evaluated at
// each method's double-precision state: what the derivative of the computed
// trajectory can at best be, since its state carries the rounding floor of
// the forward solve.
//
// The exact derivative at the exact state rounded to double shows what the
// state's representation alone costs.
//
//   build/bin/material_derivative_precision [--E 1e10] [--nu 0.499] [--dt 0.1] [--seeds 3]
//       [--adjoint auto|iterative|direct] [--json]
#include <quadmath.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/box_mesh.h"
#include "diffpd/simulator.h"
#include "diffpd/tangent_rollout.h"

namespace {

using diffpd::VectorXd;
using Quad = __float128;
constexpr int kDofs = 24;  // 8 nodes

Quad Sqrt(Quad v) { return sqrtq(v); }
Quad Abs(Quad v) { return v < 0 ? -v : v; }

struct Mat3Q {
  Quad a[3][3] = {};
};

Mat3Q Multiply(const Mat3Q& A, const Mat3Q& B) {
  Mat3Q C;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) C.a[i][j] += A.a[i][k] * B.a[k][j];
  return C;
}

Mat3Q Transpose(const Mat3Q& A) {
  Mat3Q C;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C.a[i][j] = A.a[j][i];
  return C;
}

// Symmetric A = V diag(w) V^T by cyclic Jacobi rotations.
void SymmetricEigen(Mat3Q A, Quad w[3], Mat3Q* V) {
  for (int i = 0; i < 3; ++i) V->a[i][i] = 1;
  for (int sweep = 0; sweep < 60; ++sweep) {
    if (A.a[0][1] == 0 && A.a[0][2] == 0 && A.a[1][2] == 0) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (A.a[p][q] == 0) continue;
        const Quad theta = (A.a[q][q] - A.a[p][p]) / (2 * A.a[p][q]);
        const Quad t = (theta >= 0 ? 1 : -1) / (Abs(theta) + Sqrt(theta * theta + 1));
        const Quad c = 1 / Sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {
          const Quad akp = A.a[k][p], akq = A.a[k][q];
          A.a[k][p] = c * akp - s * akq;
          A.a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const Quad apk = A.a[p][k], aqk = A.a[q][k];
          A.a[p][k] = c * apk - s * aqk;
          A.a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const Quad vkp = V->a[k][p], vkq = V->a[k][q];
          V->a[k][p] = c * vkp - s * vkq;
          V->a[k][q] = s * vkp + c * vkq;
        }
      }
  }
  for (int i = 0; i < 3; ++i) w[i] = A.a[i][i];
}

// First Piola stress of pd-corotated + pd-volume,
//   2 mu (F - R) + lambda (F - P),  R = U V^T, P = U diag(d) V^T, prod d = 1,
// for det F > 0, written F V diag(c) V^T with c from the singular values s
// (F = U diag(s) V^T): c_i = 2 mu (1 - 1 / s_i) + lambda (s_i - d_i) / s_i.
// d_i = (s_i + r_i) / 2 with r_i = sqrt(s_i^2 + 4 m) (the multiplier m by
// Newton's method on prod d = 1) and s_i - d_i = -2 m / (r_i + s_i).
Mat3Q Stress(const Mat3Q& F, Quad mu, Quad lambda) {
  Mat3Q V;
  Quad w[3], s[3];
  SymmetricEigen(Multiply(Transpose(F), F), w, &V);
  for (int i = 0; i < 3; ++i) s[i] = Sqrt(w[i]);
  Quad m = 0;
  for (int it = 0; it < 200; ++it) {
    Quad product = 1, slope = 0;
    for (int i = 0; i < 3; ++i) {
      const Quad r = Sqrt(s[i] * s[i] + 4 * m), d = (s[i] + r) / 2;
      product *= d;
      slope += 1 / (r * d);
    }
    const Quad previous = m;
    m -= (product - 1) / (product * slope);
    if (m == previous) break;
  }
  Mat3Q D;
  for (int i = 0; i < 3; ++i) {
    const Quad r = Sqrt(s[i] * s[i] + 4 * m);
    D.a[i][i] = 2 * mu * (1 - 1 / s[i]) + lambda * (-2 * m / (r + s[i])) / s[i];
  }
  return Multiply(Multiply(F, V), Multiply(D, Transpose(V)));
}

// The cell's step in quadruple precision.
struct QuadStep {
  Quad grad[8][8][3];  // Gauss point, node, axis: dN/dX
  Quad sample_volume = 0, node_mass = 0, h = 0;
  Quad x0[kDofs], v0[kDofs], force[kDofs], cx[kDofs], cv[kDofs];

  void ElasticGradient(const Quad* x, Quad mu, Quad lambda, Quad* out) const {
    for (int i = 0; i < kDofs; ++i) out[i] = 0;
    for (int q = 0; q < 8; ++q) {
      Mat3Q F;
      for (int a = 0; a < 8; ++a)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) F.a[i][j] += x[3 * a + i] * grad[q][a][j];
      const Mat3Q P = Stress(F, mu, lambda);
      for (int a = 0; a < 8; ++a)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) out[3 * a + i] += sample_volume * P.a[i][j] * grad[q][a][j];
    }
  }
  // grad g = M (x - x0 - h v0) / h^2 - f + grad E(x).
  void Residual(const Quad* x, Quad mu, Quad lambda, Quad* r) const {
    ElasticGradient(x, mu, lambda, r);
    for (int i = 0; i < kDofs; ++i) r[i] += node_mass * (x[i] - x0[i] - h * v0[i]) / (h * h) - force[i];
  }
  // Central-difference Hessian of g (row-major 24 x 24).
  std::vector<Quad> Hessian(const Quad* x, Quad mu, Quad lambda) const {
    const Quad e = 1e-14;
    std::vector<Quad> H(kDofs * kDofs);
    for (int j = 0; j < kDofs; ++j) {
      Quad xp[kDofs], xm[kDofs], rp[kDofs], rm[kDofs];
      for (int i = 0; i < kDofs; ++i) xp[i] = xm[i] = x[i];
      xp[j] += e;
      xm[j] -= e;
      Residual(xp, mu, lambda, rp);
      Residual(xm, mu, lambda, rm);
      for (int i = 0; i < kDofs; ++i) H[i * kDofs + j] = (rp[i] - rm[i]) / (2 * e);
    }
    return H;
  }
  // Newton's method from x (12 iterations: converged to quadruple rounding).
  void Solve(Quad mu, Quad lambda, Quad* x) const {
    std::vector<Quad> H;
    for (int it = 0; it < 12; ++it) {
      Quad r[kDofs];
      Residual(x, mu, lambda, r);
      if (it % 3 == 0) H = Hessian(x, mu, lambda);
      SolveLinear(H, r);
      for (int i = 0; i < kDofs; ++i) x[i] -= r[i];
    }
  }
  Quad Loss(const Quad* x1) const {
    Quad l = 0;
    for (int i = 0; i < kDofs; ++i) l += cx[i] * x1[i] + cv[i] * (x1[i] - x0[i]) / h;
    return l;
  }
  // A y = b by Gaussian elimination with partial pivoting (b overwritten).
  static void SolveLinear(std::vector<Quad> A, Quad* b) {
    const int n = kDofs;
    for (int k = 0; k < n; ++k) {
      int pivot = k;
      for (int i = k + 1; i < n; ++i)
        if (Abs(A[i * n + k]) > Abs(A[pivot * n + k])) pivot = i;
      for (int j = 0; j < n; ++j) std::swap(A[k * n + j], A[pivot * n + j]);
      std::swap(b[k], b[pivot]);
      for (int i = k + 1; i < n; ++i) {
        const Quad l = A[i * n + k] / A[k * n + k];
        for (int j = k; j < n; ++j) A[i * n + j] -= l * A[k * n + j];
        b[i] -= l * b[k];
      }
    }
    for (int k = n - 1; k >= 0; --k) {
      Quad s = b[k];
      for (int j = k + 1; j < n; ++j) s -= A[k * n + j] * b[j];
      b[k] = s / A[k * n + k];
    }
  }
};

struct Lame {
  Quad mu, lambda;
};
Lame LameOf(Quad E, Quad nu) { return {E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))}; }

// dL/dnu and dL/dE at state x1 by the implicit function theorem:
// dL/dtheta = -z . d(grad g)/dtheta, H z = cx + cv / h.
struct Derivatives {
  Quad nu = 0, youngs_modulus = 0;
};
Derivatives ImplicitDerivatives(const QuadStep& step, const Quad* x1, Quad E, Quad nu) {
  const Lame lame = LameOf(E, nu);
  Quad unit_mu[kDofs], unit_lambda[kDofs], z[kDofs];
  step.ElasticGradient(x1, 1, 0, unit_mu);
  step.ElasticGradient(x1, 0, 1, unit_lambda);
  for (int i = 0; i < kDofs; ++i) z[i] = step.cx[i] + step.cv[i] / step.h;
  QuadStep::SolveLinear(step.Hessian(x1, lame.mu, lame.lambda), z);
  Quad l_mu = 0, l_lambda = 0;
  for (int i = 0; i < kDofs; ++i) {
    l_mu -= z[i] * unit_mu[i];
    l_lambda -= z[i] * unit_lambda[i];
  }
  const Quad denominator = (1 + nu) * (1 - 2 * nu);
  Derivatives d;
  d.nu = -E / (2 * (1 + nu) * (1 + nu)) * l_mu + E * (1 + 2 * nu * nu) / (denominator * denominator) * l_lambda;
  d.youngs_modulus = l_mu / (2 * (1 + nu)) + nu / denominator * l_lambda;
  return d;
}

struct MethodResult {
  std::string method;
  double reverse_nu = 0, tangent_nu = 0, reverse_e = 0, tangent_e = 0;
  double exact_at_state_nu = 0;  // the exact derivative at the method's double state
  double state_error = 0;        // max |x1 - x1_exact| (m)
};

struct SeedResult {
  int seed = 0;
  double exact_nu = 0, exact_e = 0;
  double central_nu_error = 0, central_e_error = 0;  // central differences against the exact derivative
  double exact_at_rounded_state_nu = 0;              // the exact derivative at the exact state rounded to double
  std::vector<MethodResult> methods;
};

double Relative(double value, double exact) { return (value - exact) / std::abs(exact); }

SeedResult RunSeed(double E, double nu, double h, int seed, diffpd::AdjointSolver adjoint) {
  using namespace diffpd;
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(1, 1, 1), Vec3(0.1, 0.1, 0.1));
  scene.material.youngs_modulus = E;
  scene.material.poissons_ratio = nu;
  scene.material.density = 1e3;
  scene.gravity = Vec3(0, 0, -9.81);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  VectorXd cx(kDofs), cv(kDofs), force(kDofs);
  for (int i = 0; i < kDofs; ++i) {
    cx(i) = normal(rng);
    cv(i) = normal(rng);
    force(i) = 0.1 * 0.125 * 9.81 * normal(rng);
  }

  QuadStep step;
  const Quad g = 1 / sqrtq(3);
  int q = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k, ++q) {
        const Quad xi[3] = {i ? g : -g, j ? g : -g, k ? g : -g};
        for (int a = 0; a < 8; ++a) {
          Quad corner[3];  // the node's reference corner, from the mesh
          for (int d = 0; d < 3; ++d) corner[d] = scene.mesh.vertices(d, scene.mesh.elements(a, 0)) > 0.05 ? 1 : -1;
          for (int d = 0; d < 3; ++d) {
            Quad v = corner[d] / 8;
            for (int e = 0; e < 3; ++e)
              if (e != d) v *= 1 + corner[e] * xi[e];
            step.grad[q][a][d] = v / Quad(0.05);
          }
        }
      }
  step.sample_volume = Quad(0.05) * Quad(0.05) * Quad(0.05);
  step.node_mass = Quad(1e3) * step.sample_volume;
  step.h = h;

  SeedResult out;
  out.seed = seed;
  std::vector<VectorXd> states;
  for (const Method method : {Method::kNewtonCholesky, Method::kPdLbfgs}) {
    SolverOptions options;
    options.method = method;
    options.time_step = h;
    options.rel_tolerance = 1e-12;
    options.abs_tolerance = 1e-14;
    options.num_threads = 1;
    options.adjoint_solver = adjoint;
    Simulator sim(scene, options);
    State start = sim.RestState();
    for (int i = 0; i < 8; ++i) start.x(3 * i + 2) *= 0.9;
    if (method == Method::kNewtonCholesky)
      for (int i = 0; i < kDofs; ++i) {
        step.x0[i] = start.x(i);
        step.v0[i] = 0;
        step.force[i] = Quad(force(i)) + (i % 3 == 2 ? Quad(-9.81) * step.node_mass : Quad(0));
        step.cx[i] = cx(i);
        step.cv[i] = cv(i);
      }
    std::vector<StepInput> inputs(1);
    inputs[0].external_force = force;
    const Rollout rollout = sim.Simulate(start, inputs);
    LossGradient loss(1);
    loss.dx[1] = cx;
    loss.dv[1] = cv;
    const RolloutGradient gradient = sim.Backward(rollout, loss);
    const TangentRollout t = sim.Tangents(rollout, {InputDirection::PoissonsRatio(), InputDirection::YoungsModulus()});
    MethodResult r;
    r.method = ToString(method);
    r.reverse_nu = gradient.poissons_ratio;
    r.reverse_e = gradient.youngs_modulus;
    r.tangent_nu = cx.dot(t.dx[1].col(0)) + cv.dot(t.dv[1].col(0));
    r.tangent_e = cx.dot(t.dx[1].col(1)) + cv.dot(t.dv[1].col(1));
    out.methods.push_back(r);
    states.push_back(rollout.states[1].x);
  }

  // The exact step from Newton-Cholesky's state, its derivatives two ways.
  const Lame lame = LameOf(E, nu);
  Quad x1[kDofs];
  for (int i = 0; i < kDofs; ++i) x1[i] = states[0](i);
  step.Solve(lame.mu, lame.lambda, x1);
  const Derivatives exact = ImplicitDerivatives(step, x1, E, nu);
  out.exact_nu = static_cast<double>(exact.nu);
  out.exact_e = static_cast<double>(exact.youngs_modulus);
  auto loss_at = [&](Quad e, Quad n) {
    Quad x[kDofs];
    for (int i = 0; i < kDofs; ++i) x[i] = x1[i];
    const Lame l = LameOf(e, n);
    step.Solve(l.mu, l.lambda, x);
    return step.Loss(x);
  };
  const Quad dn = 1e-8, de = 1e-8 * E;
  const Quad central_nu = (loss_at(E, nu + dn) - loss_at(E, nu - dn)) / (2 * dn);
  const Quad central_e = (loss_at(E + de, nu) - loss_at(E - de, nu)) / (2 * de);
  out.central_nu_error = static_cast<double>(Abs(central_nu - exact.nu) / Abs(exact.nu));
  out.central_e_error = static_cast<double>(Abs(central_e - exact.youngs_modulus) / Abs(exact.youngs_modulus));
  Quad rounded[kDofs];
  for (int i = 0; i < kDofs; ++i) rounded[i] = static_cast<double>(x1[i]);
  out.exact_at_rounded_state_nu = static_cast<double>(ImplicitDerivatives(step, rounded, E, nu).nu);
  for (size_t m = 0; m < states.size(); ++m) {
    Quad xs[kDofs];
    double error = 0;
    for (int i = 0; i < kDofs; ++i) {
      xs[i] = states[m](i);
      error = std::max(error, static_cast<double>(Abs(xs[i] - x1[i])));
    }
    out.methods[m].state_error = error;
    out.methods[m].exact_at_state_nu = static_cast<double>(ImplicitDerivatives(step, xs, E, nu).nu);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  double E = 1e10, nu = 0.499, h = 0.1;
  int seeds = 3;
  bool json = false;
  diffpd::AdjointSolver adjoint = diffpd::AdjointSolver::kAuto;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return std::atof(argv[++i]);
    };
    if (arg == "--E") {
      E = value();
    } else if (arg == "--nu") {
      nu = value();
    } else if (arg == "--dt") {
      h = value();
    } else if (arg == "--seeds") {
      seeds = static_cast<int>(value());
    } else if (arg == "--adjoint" && i + 1 < argc) {
      adjoint = diffpd::ParseAdjointSolver(argv[++i]);
    } else if (arg == "--json") {
      json = true;
    } else {
      std::fprintf(stderr, "unknown option %s (--E, --nu, --dt, --seeds, --adjoint, --json)\n", arg.c_str());
      return 2;
    }
  }
  if (!(E > 0) || !(nu > -1 && nu < 0.5) || !(h > 0) || seeds < 1) {
    std::fprintf(stderr, "need E > 0, nu in (-1, 0.5), dt > 0, seeds >= 1\n");
    return 2;
  }
  std::vector<SeedResult> results;
  try {
    for (int seed = 1; seed <= seeds; ++seed) results.push_back(RunSeed(E, nu, h, seed, adjoint));
  } catch (const std::exception& e) {  // a step the library's solvers do not finish, e.g. at E = 1e12 Pa
    std::fprintf(stderr, "E = %g Pa, nu = %g, h = %g s: %s\n", E, nu, h, e.what());
    return 1;
  }

  if (json) {
    nlohmann::json out = nlohmann::json::array();
    for (const SeedResult& s : results) {
      nlohmann::json methods = nlohmann::json::array();
      for (const MethodResult& m : s.methods)
        methods.push_back({{"method", m.method},
                           {"reverse_nu", m.reverse_nu},
                           {"tangent_nu", m.tangent_nu},
                           {"reverse_youngs_modulus", m.reverse_e},
                           {"tangent_youngs_modulus", m.tangent_e},
                           {"exact_nu_at_state", m.exact_at_state_nu},
                           {"state_error_m", m.state_error}});
      out.push_back({{"E", E},
                     {"nu", nu},
                     {"dt", h},
                     {"seed", s.seed},
                     {"exact_nu", s.exact_nu},
                     {"exact_youngs_modulus", s.exact_e},
                     {"central_nu_error", s.central_nu_error},
                     {"central_youngs_modulus_error", s.central_e_error},
                     {"exact_nu_at_rounded_state", s.exact_at_rounded_state_nu},
                     {"methods", methods}});
    }
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::printf("# one cell, one step: E = %g Pa, nu = %g, h = %g s; errors relative to the exact derivative\n", E, nu,
              h);
  std::printf("%-5s %-16s %11s %11s %11s %11s %11s %11s %11s\n", "seed", "method", "rev_nu", "tan_nu", "gap_nu",
              "exact@state", "rev_E", "tan_E", "state_m");
  for (const SeedResult& s : results) {
    for (const MethodResult& m : s.methods)
      std::printf("%-5d %-16s %+11.2e %+11.2e %11.2e %+11.2e %+11.2e %+11.2e %11.2e\n", s.seed, m.method.c_str(),
                  Relative(m.reverse_nu, s.exact_nu), Relative(m.tangent_nu, s.exact_nu),
                  std::abs(m.reverse_nu - m.tangent_nu) / std::abs(s.exact_nu),
                  Relative(m.exact_at_state_nu, s.exact_nu), Relative(m.reverse_e, s.exact_e),
                  Relative(m.tangent_e, s.exact_e), m.state_error);
    std::printf(
        "#   seed %d: exact dL/dnu %.12e, dL/dE %.12e; quadruple-precision central differences agree to %.1e "
        "and %.1e; dL/dnu at the exact state rounded to double %+.1e\n",
        s.seed, s.exact_nu, s.exact_e, s.central_nu_error, s.central_e_error,
        Relative(s.exact_at_rounded_state_nu, s.exact_nu));
  }
  return 0;
}
