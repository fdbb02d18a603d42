// Stability at the extremes: every case of a reduced grid (a 4 x 1 x 1
// cantilever and a 2^3 falling cube, 20 steps) is either ok - finite,
// energy never rising, gradients matching finite differences - or stopped
// by a SolverError with a specific message; never a NaN, never a violation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <utility>
#include <sstream>

#include <nlohmann/json.hpp>

#include "tools/bench.h"
#include "diffpd/error.h"
#include "tools/stress.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

const char* const kStatusNames[] = {"maximum number of iterations reached",
                                    "line search failed",
                                    "non-finite value",
                                    "factorization failed",
                                    "inverted element",
                                    "diverged",
                                    "contact active set did not converge",
                                    "contact gained energy"};

StressOptions ReducedGrid() {
  StressOptions o;
  o.problems = {{"cantilever", -9}, {"falling-cube", -6}};  // 4 x 1 x 1 and 2 x 2 x 2 cells
  o.methods = {Method::kPd, Method::kNewtonCholesky};
  o.steps = 20;
  o.gradcheck_steps = 2;  // two steps chain the adjoint across a step boundary; three cost 1.5x
  o.threads = 1;
  return o;
}

// A failure names its status (ToString(SolverStatus)) and where it happened.
void ExpectSpecificFailure(const StressCase& c) {
  const bool names_status = std::any_of(std::begin(kStatusNames), std::end(kStatusNames),
                                        [&](const char* s) { return c.message.find(s) != std::string::npos; });
  EXPECT_TRUE(names_status) << c.message;
  const bool says_where = c.message.find("(step ") != std::string::npos ||
                          c.message.find("(energy after step ") != std::string::npos ||
                          c.message.rfind("gradient check", 0) == 0 || c.message.rfind("backward pass", 0) == 0;
  EXPECT_TRUE(says_where) << c.message;
  EXPECT_LT(c.steps_completed, 20 + 1);
}

std::string Name(const StressCase& c) {
  std::ostringstream s;
  s << c.problem << " " << c.method << " E=" << c.youngs_modulus << " nu=" << c.poissons_ratio << " h=" << c.time_step;
  return s.str();
}

// The extremes E in {1e2, 1e10} Pa, nu in {0, 0.499}, h in {1e-5, 0.1} s as
// a half fraction of the 2^3 corners in which every pair of axes meets all
// four combinations of its extremes (a strength-2 covering array), plus the
// problems' typical material and step.
TEST(StressTest, EveryExtremeCaseIsOkOrAClearSolverError) {
  const StressOptions o = ReducedGrid();
  const double corners[][3] = {{1e2, 0, 0.1},
                               {1e2, 0.499, 1e-5},
                               {1e10, 0, 1e-5},
                               {1e10, 0.499, 0.1},
                               {1e6, 0.45, 0.01}};  // the last: typical, Newton only (PD's tight solves are slow)
  std::set<std::string> tested_inputs;
  int ok = 0;
  for (const auto& p : o.problems)
    for (Method m : o.methods)
      for (const auto& [e, nu, h] : corners) {
        if (e == 1e6 && m == Method::kPd) continue;
        const StressCase c = RunStressCase(p, m, e, nu, h, o);
        SCOPED_TRACE(Name(c) + ": " + c.outcome + " " + c.message);
        ASSERT_NE(c.outcome, "violation");
        if (c.outcome == "failed") {
          ExpectSpecificFailure(c);
          continue;
        }
        ASSERT_EQ(c.outcome, "ok");
        ++ok;
        EXPECT_EQ(c.steps_completed, 20);
        EXPECT_LE(c.max_energy_excess, o.energy_tolerance);
        EXPECT_TRUE(c.gradcheck_run);
        EXPECT_LE(c.gradcheck_error, o.gradcheck_tolerance);
        EXPECT_GE(c.gradcheck_margin, 3.0) << "every resolved input at least 3x inside the tolerance";
        for (const char* input : {"x0", "v0", "external_force", "youngs_modulus", "poissons_ratio", "density"})
          if (std::find(c.gradcheck_unresolved.begin(), c.gradcheck_unresolved.end(), input) ==
              c.gradcheck_unresolved.end())
            tested_inputs.insert(input);
        EXPECT_TRUE(c.gradcheck_unresolved.empty()) << "every input resolved, by the differences or the tangent";
      }
  // Measured: 13 of 18 ok (Newton-Cholesky 9 of 10, PD 4 of 8); the rest
  // stop at PD's iteration limit or Newton's line search at E = 1e10 Pa,
  // nu = 0.499, h = 0.1 s.
  EXPECT_GE(ok, 10);
  EXPECT_EQ(tested_inputs.size(), 6u) << "every input kind is checked somewhere";
}

// The contact scenes (one cell of the bouncing ball and of the rolling
// sphere, frictional ground contact) at the same extremes with the two
// methods users run on them: each case ok - finite, its total energy never
// above its start (contact_energy_tolerance), every gradient input resolved
// with a margin of 3 - or stopped by a specific SolverError, e.g. a step
// whose pins would raise the energy (contact.h, "Energy").
TEST(StressTest, ContactScenesAtTheExtremesAreOkOrAClearSolverError) {
  StressOptions o = ReducedGrid();
  o.problems = {{"bouncing-ball", -9}, {"rolling-sphere", -9}};
  o.methods = {Method::kPdLbfgs, Method::kNewtonCholesky};
  const double corners[][3] = {{1e2, 0, 0.1}, {1e2, 0.499, 1e-5}, {1e10, 0, 1e-5}, {1e10, 0.499, 0.1}};
  int ok = 0, in_contact = 0;
  for (const auto& p : o.problems)
    for (Method m : o.methods)
      for (const auto& [e, nu, h] : corners) {
        // PD-LBFGS on the sphere only: the ball's cases take its check's time without adding a property.
        if (m == Method::kPdLbfgs && p.name == "bouncing-ball") continue;
        const StressCase c = RunStressCase(p, m, e, nu, h, o);
        SCOPED_TRACE(Name(c) + ": " + c.outcome + " " + c.message);
        ASSERT_NE(c.outcome, "violation");
        if (c.outcome == "failed") {
          ExpectSpecificFailure(c);
          continue;
        }
        ASSERT_EQ(c.outcome, "ok");
        ++ok;
        in_contact += c.contact_steps > 0;
        if (p.name == "rolling-sphere") {
          EXPECT_GT(c.contact_steps, 0) << "the sphere starts on the ground";
        }
        EXPECT_EQ(c.steps_completed, 20);
        EXPECT_LE(c.max_energy_excess, o.contact_energy_tolerance);
        EXPECT_TRUE(c.gradcheck_run);
        EXPECT_GE(c.gradcheck_margin, 3.0) << "every resolved input at least 3x inside the tolerance";
        EXPECT_TRUE(c.gradcheck_unresolved.empty());
        // PD-LBFGS is iterative: its check compares the Newton-Cholesky
        // reference, or says why not; Newton-Cholesky is its own reference.
        if (m == Method::kPdLbfgs) {
          EXPECT_NE(c.gradcheck_reference, !c.gradcheck_reference_failure.empty());
        } else {
          EXPECT_FALSE(c.gradcheck_reference);
          EXPECT_EQ(c.gradcheck_reference_failure, "");
        }
      }
  EXPECT_GE(ok, 8);
  EXPECT_GE(in_contact, 6);
}

// The long cases: 10 000 steps on the 4 x 1 x 1 cantilever and the one-cell
// rolling sphere at the corners of a grid of two time steps, the gradient
// checked on the last steps (the sphere then rests in contact). The
// extremes' long cases are in the full grid (docs/benchmarks.md): there the
// soft sphere (E = 1e2 Pa) pressed flat for 100 s gains energy under the
// check's random forces and stops with a clear SolverError.
TEST(StressTest, LongCasesAtTheCornersStayFiniteAndDissipative) {
  StressOptions o = ReducedGrid();
  o.problems = {{"cantilever", -9}, {"rolling-sphere", -9}};
  o.methods = {Method::kNewtonCholesky};
  o.youngs_moduli = {1e6};
  o.poissons_ratios = {0.3};
  o.time_steps = {1e-3, 0.01};
  o.long_steps = 10000;
  o.long_only = true;
  ASSERT_EQ(LongCaseCorners(o).size(), 2u);  // (1e6, 0.3, 0.01), (1e6, 0.3, 1e-3)
  const std::vector<StressCase> cases = RunStress(o);
  ASSERT_EQ(cases.size(), 4u);
  for (const StressCase& c : cases) {
    SCOPED_TRACE(Name(c) + ": " + c.outcome + " " + c.message);
    EXPECT_TRUE(c.long_case);
    EXPECT_EQ(c.steps, 10000);
    ASSERT_EQ(c.outcome, "ok");
    EXPECT_EQ(c.steps_completed, 10000);
    EXPECT_LE(c.max_energy_excess, c.problem == "cantilever" ? o.energy_tolerance : o.contact_energy_tolerance);
    EXPECT_GE(c.gradcheck_margin, 3.0);
    EXPECT_TRUE(c.gradcheck_unresolved.empty());
    if (c.problem == "rolling-sphere") {
      EXPECT_GT(c.contact_steps, 9000);
    }
  }
  const StressSummary summary = SummarizeStress(cases);
  EXPECT_EQ(summary.long_cases, 4);
  EXPECT_EQ(summary.contact_cases, 2);
}

TEST(StressOptionsTest, LongCaseCornersCoverEveryPairOfExtremes) {
  StressOptions o;  // E 1e2..1e10, nu 0..0.499, h 1e-5..0.1
  const std::vector<std::array<double, 3>> expected = {
      {1e2, 0, 0.1}, {1e2, 0.499, 1e-5}, {1e10, 0, 1e-5}, {1e10, 0.499, 0.1}};
  EXPECT_EQ(LongCaseCorners(o), expected);
  o.youngs_moduli = {1e6};
  o.poissons_ratios = {0.3};
  o.time_steps = {0.01};
  EXPECT_EQ(LongCaseCorners(o).size(), 1u);
  o = StressOptions();
  o.long_only = true;
  ASSERT_THROW_MESSAGE(o.Validate(), InvalidInputError, "long_only is set without long cases: give long_steps > 0");
  o.long_steps = -1;
  ASSERT_THROW_MESSAGE(o.Validate(), InvalidInputError, "long_steps = -1 is invalid: must be >= 0 (0: no long cases)");
}

// 10 000 steps on a single-cell cube: long rollouts stay finite, the energy
// never rises and the backward pass over all of them returns finite values.
TEST(StressTest, TenThousandStepsStayFiniteAndDissipative) {
  StressOptions o = ReducedGrid();
  o.steps = 10000;
  o.gradcheck_steps = 0;  // checked above; here the length matters
  const StressProblem cube{"falling-cube", -9};
  // Soft, nearly incompressible, large steps with PD; stiff, compressible,
  // tiny steps with Newton.
  const std::pair<Method, std::array<double, 3>> cases[] = {{Method::kPd, {1e2, 0.499, 0.1}},
                                                            {Method::kNewtonCholesky, {1e10, 0, 1e-5}}};
  for (const auto& [m, material] : cases) {
    const auto& [e, nu, h] = material;
    const StressCase c = RunStressCase(cube, m, e, nu, h, o);
    SCOPED_TRACE(Name(c) + ": " + c.message);
    EXPECT_EQ(c.outcome, "ok");
    EXPECT_EQ(c.steps_completed, 10000);
    EXPECT_LE(c.max_energy_excess, o.energy_tolerance);
  }
}

// A case of the full grid: a nearly incompressible, very
// stiff cantilever at h = 0.01 s whose second step's predictor is so
// compressed that Newton's descent from it can end at a far stationary point
// (5.6e6 J for a body with 12 J): without the energy bound the total energy
// rises by 0.96 (relative) without an error. A result with g above g(x_i),
// the previous total energy, is solved again from x_i
// (SolverOptions::bound_step_energy).
TEST(StressTest, StiffIncompressibleStepsDoNotClimbToAFarStationaryPoint) {
  StressOptions o = ReducedGrid();
  o.steps = 5;
  o.gradcheck_steps = 0;
  for (Method m : {Method::kNewtonCholesky, Method::kPdLbfgs}) {
    const StressCase c = RunStressCase({"cantilever", -6}, m, 1e10, 0.499, 0.01, o);
    SCOPED_TRACE(Name(c) + ": " + c.message);
    // Newton completes; PD-LBFGS may stop at the rounding floor (a clear error).
    if (m == Method::kNewtonCholesky) {
      EXPECT_EQ(c.outcome, "ok");
    }
    EXPECT_NE(c.outcome, "violation");
    if (c.outcome == "ok") {
      EXPECT_LE(c.max_energy_excess, o.energy_tolerance);
    }
  }
}

// Symplectic Euler beyond its stability limit: the energy explodes; the case
// must end in a SolverError (diverged: a body torn beyond
// SolverOptions::max_extent_ratio), not in a NaN state.
TEST(StressTest, ExplicitIntegrationBeyondItsStabilityLimitFailsClearly) {
  StressOptions o = ReducedGrid();
  o.steps = 10000;
  const StressCase c = RunStressCase({"falling-cube", -6}, Method::kSemiImplicit, 1e10, 0.3, 1e-3, o);
  EXPECT_EQ(c.outcome, "failed") << c.message;
  EXPECT_NE(c.message.find("diverged"), std::string::npos) << c.message;
  EXPECT_LT(c.steps_completed, 10000);
}

// A very stiff cube falling freely at h = 0.1 s: after ~2.5 s it is 30 m
// from the origin, its deformation gradients are formed from positions of
// that size, and |grad g| cannot get below the report's automatic tolerance.
// Without the rounding-floor acceptance Newton's line search stops there
// (steps 26-29 of 50); those steps end at the rounding floor and the case
// completes.
TEST(StressTest, StiffFallingCubeFarFromTheOriginCompletesAtTheRoundingFloor) {
  StressOptions o;
  o.problems = {{"falling-cube", -6}};
  o.methods = {Method::kNewtonCholesky};
  o.youngs_moduli = {1e10};
  o.poissons_ratios = {0.3};
  o.time_steps = {0.1};
  o.steps = 32;
  o.gradcheck_steps = 0;
  o.threads = 1;
  const std::vector<StressCase> cases = RunStress(o);
  ASSERT_EQ(cases.size(), 1u);
  EXPECT_EQ(cases[0].outcome, "ok") << cases[0].message;
  EXPECT_EQ(cases[0].steps_completed, 32);
  EXPECT_GT(cases[0].rounding_floor_steps, 0);
}

// The stiff cube in free fall with newton-pcg (gradcheck_test.cc has the
// same case): its density derivative nearly cancels, and the check's solves
// at rel_tolerance 1e-10 put it 4.8e-3 from the converged reference while
// the differences confirm the adjoint. The case is ok, and its JSON names
// the input that the tighter forward settled.
TEST(StressTest, AReferenceDisagreementSettledByATighterForwardIsOkAndListed) {
  StressOptions o;
  o.problems = {{"falling-cube", -6}};
  o.methods = {Method::kNewtonPcg};
  o.youngs_moduli = {1e10};
  o.poissons_ratios = {0};
  o.time_steps = {1e-3};
  o.steps = 5;
  o.gradcheck_rel_tolerance = 1e-10;
  o.threads = 1;
  const std::vector<StressCase> cases = RunStress(o);
  ASSERT_EQ(cases.size(), 1u);
  EXPECT_EQ(cases[0].outcome, "ok") << cases[0].message;
  EXPECT_TRUE(cases[0].gradcheck_reference) << cases[0].gradcheck_reference_failure;
  EXPECT_NE(std::find(cases[0].gradcheck_tightened.begin(), cases[0].gradcheck_tightened.end(), "density"),
            cases[0].gradcheck_tightened.end());
  EXPECT_GE(cases[0].gradcheck_margin, 3.0);
  const nlohmann::json rows = nlohmann::json::parse(StressToJson(cases).dump());
  EXPECT_EQ(rows[0].at("gradcheck_tightened"), nlohmann::json(cases[0].gradcheck_tightened));
}

TEST(StressTest, RunStressCoversTheGridAndWritesJson) {
  StressOptions o = ReducedGrid();
  o.problems = {{"falling-cube", -9}};
  o.methods = {Method::kNewtonCholesky};
  o.youngs_moduli = {1e4, 1e6};
  o.poissons_ratios = {0.3};
  o.time_steps = {1e-2};
  o.steps = 5;
  const auto cases = RunStress(o);
  ASSERT_EQ(cases.size(), 2u);
  EXPECT_EQ(cases[1].youngs_modulus, 1e6);
  const nlohmann::json rows = nlohmann::json::parse(StressToJson(cases).dump());
  EXPECT_EQ(rows[0].at("outcome"), "ok");
  EXPECT_EQ(rows[0].at("steps_completed"), 5);
  EXPECT_EQ(rows[0].at("rounding_floor_steps"), 0);
  EXPECT_EQ(rows[0].at("newton_fallback_steps"), 0);
  EXPECT_TRUE(rows[0].at("gradcheck_unresolved").is_array());
  EXPECT_EQ(rows[0].at("gradcheck_run"), true);
  EXPECT_GE(rows[0].at("gradcheck_margin").get<double>(), 3.0);
  EXPECT_EQ(rows[0].at("gradcheck_reference"), false) << "Newton-Cholesky is not checked against itself";
  EXPECT_EQ(rows[0].at("gradcheck_reference_failure"), "");
  EXPECT_TRUE(rows[0].at("gradcheck_tightened").empty()) << "no reference, so nothing to settle";
  const StressSummary summary = SummarizeStress(cases);
  EXPECT_EQ(summary.cases, 2);
  EXPECT_EQ(summary.gradchecks, 2);
  EXPECT_EQ(summary.unresolved_cases, 0);
  EXPECT_GE(summary.min_gradcheck_margin, 3.0);
}

TEST(StressOptionsTest, ValidateNamesTheFieldValueAndRange) {
  StressOptions o;
  o.poissons_ratios = {0.5};
  ASSERT_THROW_MESSAGE(o.Validate(), InvalidInputError,
                       "poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");
  o = StressOptions();
  o.time_steps = {0};
  EXPECT_THROW(o.Validate(), InvalidInputError);
  o = StressOptions();
  o.threads = 99999;
  try {
    o.Validate();
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.what(), "threads = 99999 is invalid: must be " + ThreadRange());
  }
  o = StressOptions();
  o.problems = {{"no-such-problem", 0}};
  EXPECT_THROW(RunStress(o), InvalidInputError);
}

TEST(AutoAbsToleranceTest, GrowsWithStiffnessAndInverseTimeStepAndNeverFallsBelowTheDefault) {
  Scene scene = MakeRefinedProblem("falling-cube", -6)->MakeScene();
  EXPECT_EQ(AutoAbsTolerance(scene, 1e-2), 1e-9);  // E = 1e5 Pa: the default holds
  scene.material.youngs_modulus = 1e10;
  const double stiff = AutoAbsTolerance(scene, 1e-2);
  EXPECT_GT(stiff, 1e-9);
  scene.material.poissons_ratio = 0.499;  // lambda grows 180-fold over nu = 0.4
  EXPECT_GT(AutoAbsTolerance(scene, 1e-2), 50 * stiff);
  scene.material.youngs_modulus = 1e2;
  EXPECT_GT(AutoAbsTolerance(scene, 1e-5), AutoAbsTolerance(scene, 1e-3));
}

}  // namespace
}  // namespace diffpd::problems
