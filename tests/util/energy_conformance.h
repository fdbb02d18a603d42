// The conformance check every energy, projection and state force passes.
//
// A term is described by plain callables on a state vector y (a deformation
// gradient flattened column-major, a body's node positions, positions and
// velocities and parameters, ...), and the check asserts, at several seeded
// random states, the properties that any correct implementation has:
//
//  EnergyTerm E(y) with gradient g(y) and Hessian product H(y) z:
//   - zero at rest: E(rest) = 0 and g(rest) = 0 (when the term has a rest state);
//   - each symmetry (frame indifference: E(Q y) = E(y) for rotations Q, and
//     g(Q y) = Q g(y));
//   - the gradient against central differences of E;
//   - the Hessian product against central differences of g, and its symmetry
//     z1 . H z2 = z2 . H z1.
//  ForceTerm F(y) with vector-Jacobian product (dF/dy)^T w:
//   - zero at rest: F(rest) = 0;
//   - each symmetry: F(Q y) = Q F(y) (the action on forces given separately);
//   - the force differential: w . (dF/dy) d against central differences.
//  ProjectionTerm P(y) with differential (dP/dy) z:
//   - the projection lands in its set (when a violation measure is given);
//   - idempotence P(P(y)) = P(y);
//   - each symmetry: P(Q y) = Q P(y);
//   - the differential against central differences of P.
//
// Derivatives are checked with the central-difference policy of
// central_difference.h (the step from the term's noise level, errors relative
// to the derivative, floored at the noise floor): the whole Jacobian when y
// has at most ConformanceOptions::full_jacobian_size entries, else along
// `directions` random directions per state. Exact properties (rest,
// symmetries, idempotence, Hessian symmetry) hold to invariance_rtol times the
// term's scale. The result lists every property checked with its verdict;
// Conforms() makes it a gtest assertion:
//
//   EXPECT_TRUE(Conforms(CheckEnergyConformance(term)));
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "diffpd/types.h"
#include "util/central_difference.h"

namespace diffpd::testing {

// A rotation acting on a term's states (and, for forces and projections, on
// its values): y -> act(y, Q). Must be linear in y for the gradient law.
struct Symmetry {
  std::string name;  // e.g. "frame rotation", "material rotation", "rotation about the wall normal"
  std::function<VectorXd(const VectorXd& y, const Mat3& q)> act;
  // The action on values (forces, projections); empty: the same as act.
  std::function<VectorXd(const VectorXd& value, const Mat3& q)> act_on_value;
  // Draws Q; empty: a uniformly random rotation.
  std::function<Mat3(std::mt19937_64* rng)> draw;
};

// Q y for y the concatenation of 3-vectors (node positions, velocities).
VectorXd RotateEach3(const VectorXd& y, const Mat3& q);
// A uniformly random rotation.
Mat3 RandomRotation(std::mt19937_64* rng);
// A random rotation about the unit axis n.
Mat3 RandomRotationAbout(const Vec3& n, std::mt19937_64* rng);

// How a term's noise and scales are judged (see central_difference.h).
struct TermScales {
  // Relative noise of one evaluation (rounding: 1e-15).
  double noise = 1e-15;
  // The magnitude of the terms the value sums (J, N, ...), which rounding is
  // relative to, at state y; empty: |value(y)|. Near rest an energy is tiny
  // against its terms (mu (sigma - 1)^2 vs mu sigma^2): give it.
  std::function<double(const VectorXd& y)> value;
  // The scale over which the term changes at state y (the input_scale of
  // the step rule: element size for node positions, DeformationScale for a
  // deformation gradient); empty: |y|_inf.
  std::function<double(const VectorXd& y)> input;
};

struct EnergyTerm {
  std::string name;
  std::function<double(const VectorXd& y)> energy;
  std::function<VectorXd(const VectorXd& y)> gradient;
  std::function<VectorXd(const VectorXd& y, const VectorXd& z)> hessian_product;  // (d^2E/dy^2)(y) z
  std::function<VectorXd(std::mt19937_64* rng)> random_state;                     // where E is smooth
  std::optional<VectorXd> rest;  // E = 0 and g = 0 there; none: no such state
  std::vector<Symmetry> symmetries;
  TermScales scales;
};

struct ForceTerm {
  std::string name;
  std::function<VectorXd(const VectorXd& y)> force;
  std::function<VectorXd(const VectorXd& y, const VectorXd& w)> vjp;  // (dF/dy)^T w
  std::function<VectorXd(std::mt19937_64* rng)> random_state;
  std::optional<VectorXd> rest;  // F = 0 there
  std::vector<Symmetry> symmetries;
  TermScales scales;
};

struct ProjectionTerm {
  std::string name;
  std::function<VectorXd(const VectorXd& y)> project;
  std::function<VectorXd(const VectorXd& y, const VectorXd& z)> differential;  // (dP/dy)(y) z
  std::function<VectorXd(std::mt19937_64* rng)> random_state;
  // How far a point is from the set (0 on it, same units as y); empty: not checked.
  std::function<double(const VectorXd& p)> violation;
  std::vector<Symmetry> symmetries;
  TermScales scales;
};

struct ConformanceOptions {
  int states = 4;                  // random states per term
  int directions = 2;              // random directions per state (large y)
  int full_jacobian_size = 12;     // whole Jacobians up to this many entries of y
  std::uint64_t seed = 20211;      // seeds the states, directions and rotations
  double rtol = 1e-6;              // derivatives vs central differences
  double invariance_rtol = 1e-12;  // exact properties, relative to the term's scale
};

// One property at one state.
struct ConformanceProperty {
  std::string name;  // e.g. "gradient at state 2"
  bool passed = false;
  std::string detail;
  std::optional<DifferenceCheck> difference;  // derivative checks
};

struct ConformanceResult {
  std::string term;
  std::vector<ConformanceProperty> properties;
  bool passed() const;
  // The smallest margin of the derivative checks (infinite if none).
  double min_margin() const;
  // The term, then every failed property (all with verbose) one per line.
  std::string Describe(bool verbose = false) const;
};

ConformanceResult CheckEnergyConformance(const EnergyTerm& term, const ConformanceOptions& options = {});
ConformanceResult CheckForceConformance(const ForceTerm& term, const ConformanceOptions& options = {});
ConformanceResult CheckProjectionConformance(const ProjectionTerm& term, const ConformanceOptions& options = {});

// Success when every property passed; the message lists the failed ones.
// Marginal derivative checks are noted on stdout as by Passes().
::testing::AssertionResult Conforms(const ConformanceResult& result);

}  // namespace diffpd::testing
