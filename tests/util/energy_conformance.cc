#include "util/energy_conformance.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <sstream>

namespace diffpd::testing {
namespace {

std::string Format(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", v);
  return buffer;
}

double InfNorm(const VectorXd& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

VectorXd NormalVector(Eigen::Index n, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

// The states and scales shared by the three checks.
struct Setup {
  std::vector<VectorXd> states;
  const TermScales* scales;
  double Input(const VectorXd& y) const {
    if (scales->input) return scales->input(y);
    const double s = InfNorm(y);
    return s > 0 ? s : 1.0;
  }
  // The value scale at y, or `measured` when the term gives none.
  double Value(const VectorXd& y, double measured) const { return scales->value ? scales->value(y) : measured; }
  DifferenceOptions Differences(const VectorXd& y, double value_scale, const ConformanceOptions& o) const {
    DifferenceOptions d;
    d.noise = scales->noise;
    d.rtol = o.rtol;
    d.input_scale = Input(y);
    d.value_scale = value_scale;  // 0: measured by the check
    return d;
  }
};

Setup DrawStates(const std::function<VectorXd(std::mt19937_64*)>& random_state, const TermScales& scales,
                 const ConformanceOptions& o, std::mt19937_64* rng) {
  Setup s{{}, &scales};
  for (int k = 0; k < o.states; ++k) s.states.push_back(random_state(rng));
  return s;
}

Mat3 Draw(const Symmetry& symmetry, std::mt19937_64* rng) {
  return symmetry.draw ? symmetry.draw(rng) : RandomRotation(rng);
}

VectorXd ActOnValue(const Symmetry& symmetry, const VectorXd& value, const Mat3& q) {
  return symmetry.act_on_value ? symmetry.act_on_value(value, q) : symmetry.act(value, q);
}

// |error| <= tolerance as a property.
void AddBound(ConformanceResult* r, const std::string& name, double error, double tolerance, const std::string& what) {
  ConformanceProperty p;
  p.name = name;
  p.passed = error <= tolerance;  // false for NaN
  p.detail = what + " = " + Format(error) + (p.passed ? " <= " : " > ") + "tolerance " + Format(tolerance);
  r->properties.push_back(p);
}

void AddDifference(ConformanceResult* r, const std::string& name, const DifferenceCheck& check) {
  ConformanceProperty p;
  p.name = name;
  p.passed = check.passed();
  p.detail = check.Describe();
  p.difference = check;
  r->properties.push_back(p);
}

// The Jacobian of a linear map given by its products with the unit vectors.
MatrixXd Columns(Eigen::Index n, const std::function<VectorXd(const VectorXd&)>& apply) {
  MatrixXd j;
  for (Eigen::Index c = 0; c < n; ++c) {
    const VectorXd column = apply(VectorXd::Unit(n, c));
    if (c == 0) j.resize(column.size(), n);
    j.col(c) = column;
  }
  return j;
}

std::string At(const std::string& property, int state) { return property + " at state " + std::to_string(state); }

}  // namespace

VectorXd RotateEach3(const VectorXd& y, const Mat3& q) {
  VectorXd out(y.size());
  for (Eigen::Index i = 0; i + 2 < y.size(); i += 3) out.segment<3>(i) = q * y.segment<3>(i);
  return out;
}

Mat3 RandomRotation(std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(*rng), normal(*rng), normal(*rng), normal(*rng)).normalized().toRotationMatrix();
}

Mat3 RandomRotationAbout(const Vec3& n, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  return Eigen::AngleAxisd(angle(*rng), n.normalized()).toRotationMatrix();
}

bool ConformanceResult::passed() const {
  return std::all_of(properties.begin(), properties.end(), [](const ConformanceProperty& p) { return p.passed; });
}

double ConformanceResult::min_margin() const {
  double m = std::numeric_limits<double>::infinity();
  for (const ConformanceProperty& p : properties)
    if (p.difference) m = std::min(m, p.difference->margin());
  return m;
}

std::string ConformanceResult::Describe(bool verbose) const {
  std::ostringstream s;
  int failed = 0;
  for (const ConformanceProperty& p : properties) failed += !p.passed;
  s << term << ": " << properties.size() << " properties checked, " << failed << " failed, smallest derivative margin "
    << Format(min_margin());
  for (const ConformanceProperty& p : properties)
    if (verbose || !p.passed) s << "\n  " << (p.passed ? "ok     " : "FAILED ") << p.name << ": " << p.detail;
  return s.str();
}

ConformanceResult CheckEnergyConformance(const EnergyTerm& t, const ConformanceOptions& o) {
  ConformanceResult r{t.name, {}};
  std::mt19937_64 rng(o.seed);
  const Setup s = DrawStates(t.random_state, t.scales, o, &rng);
  double typical_value = 0, typical_gradient = 0;
  for (const VectorXd& y : s.states) {
    typical_value = std::max(typical_value, s.Value(y, std::abs(t.energy(y))));
    typical_gradient = std::max(typical_gradient, t.gradient(y).norm());
  }
  if (t.rest) {
    const VectorXd& y = *t.rest;
    AddBound(&r, "zero energy at rest", std::abs(t.energy(y)), o.invariance_rtol * typical_value, "|E(rest)|");
    AddBound(&r, "zero gradient at rest", t.gradient(y).norm(), o.invariance_rtol * typical_gradient, "|g(rest)|");
  }
  for (size_t k = 0; k < s.states.size(); ++k) {
    const VectorXd& y = s.states[k];
    const int state = static_cast<int>(k);
    const double e = t.energy(y);
    const VectorXd g = t.gradient(y);
    const double value = s.Value(y, std::abs(e));
    const double gradient_scale = std::max(g.norm(), value / s.Input(y));
    for (const Symmetry& symmetry : t.symmetries) {
      const Mat3 q = Draw(symmetry, &rng);
      const VectorXd qy = symmetry.act(y, q);
      AddBound(&r, At("invariance under " + symmetry.name, state), std::abs(t.energy(qy) - e),
               o.invariance_rtol * std::max(value, s.Value(qy, std::abs(e))), "|E(Q y) - E(y)|");
      AddBound(&r, At("gradient covariance under " + symmetry.name, state),
               (t.gradient(qy) - ActOnValue(symmetry, g, q)).norm(), o.invariance_rtol * gradient_scale,
               "|g(Q y) - Q g(y)|");
    }
    const DifferenceOptions energy_options = s.Differences(y, t.scales.value ? value : 0.0, o);
    const DifferenceOptions gradient_options = s.Differences(y, t.scales.value ? value / s.Input(y) : 0.0, o);
    const auto apply_h = [&](const VectorXd& z) { return t.hessian_product(y, z); };
    if (y.size() <= o.full_jacobian_size) {
      AddDifference(&r, At("gradient", state), CheckGradient(t.energy, y, g, energy_options));
      AddDifference(&r, At("Hessian", state),
                    CheckJacobian(t.gradient, y, Columns(y.size(), apply_h), gradient_options));
    } else {
      for (int d = 0; d < o.directions; ++d) {
        const VectorXd dir = NormalVector(y.size(), &rng);
        AddDifference(&r, At("gradient", state),
                      CheckDirectionalDerivative(t.energy, y, dir, g.dot(dir), energy_options));
        AddDifference(&r, At("Hessian", state),
                      CheckDirectionalDerivative(t.gradient, y, dir, apply_h(dir), gradient_options));
      }
    }
    const VectorXd z1 = NormalVector(y.size(), &rng), z2 = NormalVector(y.size(), &rng);
    const VectorXd h1 = apply_h(z1), h2 = apply_h(z2);
    AddBound(&r, At("Hessian symmetry", state), std::abs(z2.dot(h1) - z1.dot(h2)),
             o.invariance_rtol * (h1.norm() * z2.norm() + h2.norm() * z1.norm()), "|z2 . H z1 - z1 . H z2|");
  }
  return r;
}

ConformanceResult CheckForceConformance(const ForceTerm& t, const ConformanceOptions& o) {
  ConformanceResult r{t.name, {}};
  std::mt19937_64 rng(o.seed);
  const Setup s = DrawStates(t.random_state, t.scales, o, &rng);
  double typical_value = 0;
  for (const VectorXd& y : s.states) typical_value = std::max(typical_value, s.Value(y, t.force(y).norm()));
  if (t.rest)
    AddBound(&r, "zero force at rest", t.force(*t.rest).norm(), o.invariance_rtol * typical_value, "|F(rest)|");
  for (size_t k = 0; k < s.states.size(); ++k) {
    const VectorXd& y = s.states[k];
    const int state = static_cast<int>(k);
    const VectorXd f = t.force(y);
    const double value = s.Value(y, f.norm());
    for (const Symmetry& symmetry : t.symmetries) {
      const Mat3 q = Draw(symmetry, &rng);
      AddBound(&r, At("covariance under " + symmetry.name, state),
               (t.force(symmetry.act(y, q)) - ActOnValue(symmetry, f, q)).norm(),
               o.invariance_rtol * std::max(value, f.norm()), "|F(Q y) - Q F(y)|");
    }
    if (y.size() <= o.full_jacobian_size) {
      // Rows of dF/dy from the vector-Jacobian products with the unit vectors.
      const MatrixXd jt = Columns(f.size(), [&](const VectorXd& w) { return t.vjp(y, w); });
      AddDifference(&r, At("force differential", state),
                    CheckJacobian(t.force, y, jt.transpose(), s.Differences(y, t.scales.value ? value : 0.0, o)));
    } else {
      for (int d = 0; d < o.directions; ++d) {
        const VectorXd dir = NormalVector(y.size(), &rng), w = NormalVector(f.size(), &rng);
        const auto wf = [&](const VectorXd& x) { return w.dot(t.force(x)); };
        AddDifference(
            &r, At("force differential", state),
            CheckDirectionalDerivative(wf, y, dir, t.vjp(y, w).dot(dir), s.Differences(y, value * w.norm(), o)));
      }
    }
  }
  return r;
}

ConformanceResult CheckProjectionConformance(const ProjectionTerm& t, const ConformanceOptions& o) {
  ConformanceResult r{t.name, {}};
  std::mt19937_64 rng(o.seed);
  const Setup s = DrawStates(t.random_state, t.scales, o, &rng);
  for (size_t k = 0; k < s.states.size(); ++k) {
    const VectorXd& y = s.states[k];
    const int state = static_cast<int>(k);
    const VectorXd p = t.project(y);
    const double scale = std::max(p.norm(), s.Input(y));
    if (t.violation)
      AddBound(&r, At("projection in the set", state), std::abs(t.violation(p)), o.invariance_rtol * scale,
               "violation");
    AddBound(&r, At("idempotence", state), (t.project(p) - p).norm(), o.invariance_rtol * scale, "|P(P(y)) - P(y)|");
    for (const Symmetry& symmetry : t.symmetries) {
      const Mat3 q = Draw(symmetry, &rng);
      AddBound(&r, At("equivariance under " + symmetry.name, state),
               (t.project(symmetry.act(y, q)) - ActOnValue(symmetry, p, q)).norm(), o.invariance_rtol * scale,
               "|P(Q y) - Q P(y)|");
    }
    const auto apply_d = [&](const VectorXd& z) { return t.differential(y, z); };
    const DifferenceOptions options = s.Differences(y, t.scales.value ? s.Value(y, p.norm()) : 0.0, o);
    if (y.size() <= o.full_jacobian_size) {
      AddDifference(&r, At("differential", state), CheckJacobian(t.project, y, Columns(y.size(), apply_d), options));
    } else {
      for (int d = 0; d < o.directions; ++d) {
        const VectorXd dir = NormalVector(y.size(), &rng);
        AddDifference(&r, At("differential", state),
                      CheckDirectionalDerivative(t.project, y, dir, apply_d(dir), options));
      }
    }
  }
  return r;
}

::testing::AssertionResult Conforms(const ConformanceResult& result) {
  for (const ConformanceProperty& p : result.properties)
    if (p.passed && p.difference && p.difference->marginal())
      std::cout << "[ MARGINAL ] " << result.term << ", " << p.name << ": " << p.detail << std::endl;
  if (!result.passed()) return ::testing::AssertionFailure() << result.Describe();
  return ::testing::AssertionSuccess() << result.Describe();
}

}  // namespace diffpd::testing
