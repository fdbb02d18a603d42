// The rollout gradient check: on a small beam, pd-lbfgs and newton-cholesky
// at the recommended solve tolerance pass every input kind with a margin of
// at least 10 (pd-lbfgs also against the Newton-Cholesky reference); an
// inaccurate adjoint fails, and says against what; where the differences
// cannot resolve a derivative with margin (h = 1e-5 s) the forward-mode
// tangent decides it; differences hold the checked rollout's quad faces and
// resolve across their jumps; a weak pass is widened where wider steps
// resolve it better; perturbed rollouts run three at once give the same
// verdicts; a reference that converges to another solution of the implicit
// steps is not compared; a reference that disagrees only by the forward's
// tolerance (it agrees with the method's gradient at a tighter one) does not
// fail a decisive pass; the reports and the progress calls carry the
// result's numbers;
// bad options are refused with exact messages.
#include "tools/gradcheck.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "diffpd/error.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/simulator.h"
#include "problem_registry.h"
#include "tools/bench.h"
#include "tools/stress.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

SolverOptions CheckOptions(Method method) {
  SolverOptions o = testing::TightOptions(method);
  o.rel_tolerance = RecommendedGradCheckRelTolerance(method);
  o.backward_rel_tolerance = 1e-12;
  return o;
}

GradCheckResult Check(const SolverOptions& options, const GradCheckOptions& check = GradCheckOptions()) {
  const Scene scene = testing::SmallBeamScene();
  Simulator sim(scene, options);
  return CheckRolloutGradient(scene, options, testing::MovingStart(sim), 3, check);
}

// A registered problem's scene and initial state with semi-implicit Euler at
// step h (0: the problem's own), one thread.
struct SemiImplicitCase {
  Scene scene;
  SolverOptions options;
  State initial;
};
SemiImplicitCase SemiImplicit(const std::string& name, double h = 0) {
  const auto problem = MakeProblem(name);
  SemiImplicitCase c;
  c.options.method = Method::kSemiImplicit;
  c.options.time_step = h > 0 ? h : problem->default_time_step();
  c.options.num_threads = 1;
  c.scene = problem->MakeScene();
  Simulator sim(c.scene, c.options);
  c.initial = problem->InitialState(sim);
  return c;
}

class GradCheckMethodTest : public ::testing::TestWithParam<Method> {};

TEST_P(GradCheckMethodTest, EveryInputKindPassesWithAMarginOfAtLeastTen) {
  const Method method = GetParam();
  const GradCheckResult r = Check(CheckOptions(method));
  EXPECT_EQ(r.method, ToString(method));
  EXPECT_EQ(r.verdict, CheckVerdict::kPass) << GradCheckTable(r);
  EXPECT_GE(r.min_margin, 10.0) << GradCheckTable(r);
  EXPECT_EQ(r.inputs.size(), 6u);
  for (const auto& e : r.inputs) {
    SCOPED_TRACE(e.input);
    EXPECT_EQ(e.verdict, CheckVerdict::kPass) << e.reason;
    EXPECT_EQ(e.directions, e.entries == 1 ? 1 : 2);  // scalar parameters: one direction
    EXPECT_LE(e.error * 10, r.tolerance);
    EXPECT_LE(e.floor * 10, r.tolerance);
    EXPECT_GT(e.step, 0.0);
  }
  // The iterative method is compared with a converged Newton-Cholesky
  // rollout by default; Newton-Cholesky itself is not.
  EXPECT_EQ(r.reference, method == Method::kPdLbfgs);
  for (const auto& e : r.inputs) {
    if (r.reference) {
      EXPECT_LE(e.reference_error, 1e-6) << e.input;
    } else {
      EXPECT_TRUE(std::isnan(e.reference_error)) << e.input;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, GradCheckMethodTest, ::testing::Values(Method::kPdLbfgs, Method::kNewtonCholesky),
                         [](const ::testing::TestParamInfo<Method>& info) {
                           return info.param == Method::kPdLbfgs ? std::string("pd_lbfgs")
                                                                 : std::string("newton_cholesky");
                         });

// An adjoint stopped at a relative residual of 0.3 gives a gradient wrong by
// far more than the tolerance: the differences and the reference both catch it.
TEST(GradCheckTest, AnInaccurateAdjointFails) {
  SolverOptions options = CheckOptions(Method::kPdLbfgs);
  options.backward_rel_tolerance = 0.3;
  const GradCheckResult r = Check(options);
  EXPECT_EQ(r.verdict, CheckVerdict::kFail) << GradCheckTable(r);
  EXPECT_GE(r.Count(CheckVerdict::kFail), 1);
  EXPECT_LT(r.min_margin, 1.0);
  bool reference_named = false;
  for (const auto& e : r.inputs)
    if (e.verdict == CheckVerdict::kFail)
      reference_named = reference_named || e.reason.rfind("differs from the Newton-Cholesky reference by ", 0) == 0;
  EXPECT_TRUE(reference_named) << GradCheckTable(r);
  // Without the reference, the differences alone catch it.
  GradCheckOptions no_reference;
  no_reference.reference = false;
  const GradCheckResult d = Check(options, no_reference);
  EXPECT_EQ(d.verdict, CheckVerdict::kFail) << GradCheckTable(d);
  for (const auto& e : d.inputs)
    if (e.verdict == CheckVerdict::kFail) {
      EXPECT_EQ(e.reason.rfind("differs by ", 0), 0u) << e.reason;
    }
}

// At h = 1e-5 s the final velocity carries the positions' rounding times
// 1/h, which buries the material derivatives of three steps: the
// differences resolve the material derivatives with margins below
// decisive_margin (10) at best, and the forward-mode tangent on the same
// states decides them (the gradient agrees with it to rounding).
TEST(GradCheckTest, TheTangentDecidesWhatTheDifferencesCannotResolve) {
  SolverOptions options = CheckOptions(Method::kNewtonCholesky);
  options.time_step = 1e-5;
  GradCheckOptions check;
  check.directions = 1;
  const GradCheckResult r = Check(options, check);
  EXPECT_TRUE(r.tangent);
  EXPECT_EQ(r.verdict, CheckVerdict::kPass) << GradCheckTable(r);
  EXPECT_GE(r.min_margin, 10.0) << GradCheckTable(r);
  int by_tangent = 0;
  for (const auto& e : r.inputs) {
    EXPECT_LE(e.tangent_error, 1e-8) << e.input;  // the adjoint is exact for these states
    if (e.basis == "tangent") {
      ++by_tangent;
      EXPECT_GT(std::max(e.error, e.floor), check.tolerance / check.decisive_margin)
          << e.input << ": the differences did not decide";
      EXPECT_EQ(e.reason.rfind("differences ", 0), 0u) << e.reason;
    }
  }
  EXPECT_GE(by_tangent, 1) << GradCheckTable(r);
  // Without the tangent the differences alone (widened to 0.3 of the
  // scale) resolve the material derivatives only barely: margins below 3.
  check.tangent = false;
  const GradCheckResult d = Check(options, check);
  EXPECT_EQ(d.Count(CheckVerdict::kFail), 0) << GradCheckTable(d);
  EXPECT_LT(d.min_margin, 3.0) << GradCheckTable(d);
}

// A free beam gliding along x through still water (quad hydrodynamics on
// its boundary faces): its side faces move exactly along their own planes,
// so the water does not meet them, and any perturbation of v0 turns some of
// them into the water, where the force jumps (Cd and Ct are not zero at
// grazing incidence). The check holds each step's faces at the checked
// rollout's, so its differences are those of the checked rollout's smooth
// piece: without the tangent every input, v0 included, passes on the
// differences alone with a margin of at least 10. Left to their states the
// perturbed rollouts measure the jump: v0 then fails, its differences 0.68
// relative off against a floor of 0.11.
TEST(GradCheckTest, DifferencesHoldTheCheckedRolloutsQuadFacesAndResolveAcrossTheirJumps) {
  Scene scene = testing::SmallBeamScene();
  scene.dirichlet = DirichletBoundary();
  scene.gravity = Vec3::Zero();
  scene.quad_hydrodynamics = QuadHydrodynamics();
  scene.quad_hydrodynamics->quads = BoundaryQuads(scene.mesh);
  const SolverOptions options = CheckOptions(Method::kNewtonCholesky);
  Simulator sim(scene, options);
  State start = sim.RestState();
  for (int i = 0; i < start.v.size() / 3; ++i) start.v(3 * i) = 0.5;  // m/s
  GradCheckOptions check;
  check.directions = 1;
  check.tangent = false;
  const GradCheckResult d = CheckRolloutGradient(scene, options, start, 3, check);
  EXPECT_EQ(d.verdict, CheckVerdict::kPass) << GradCheckTable(d);
  EXPECT_GE(d.min_margin, 10.0) << GradCheckTable(d);
  for (const auto& e : d.inputs) EXPECT_EQ(e.basis, "differences") << e.input;
}

// Semi-implicit Euler on calibrate-plant at h = 1e-4 s: over three tiny
// steps Poisson's ratio barely moves the loss, and its differences at the
// usual steps pass with a margin of only 5.7 (the loss's rounding). Where a
// pass's margin is below widen_below_margin the check also takes the two
// wider steps, whose noise is 3x and 30x lower, and keeps them where they
// pass with a larger margin: 17 here. (Without the tangent, which would
// decide a margin below decisive_margin.)
TEST(GradCheckTest, AWeakPassIsWidenedWhereWiderStepsResolveItBetter) {
  const SemiImplicitCase c = SemiImplicit("calibrate-plant", 1e-4);
  const Scene& scene = c.scene;
  const SolverOptions& options = c.options;
  const State& initial = c.initial;
  auto poissons_ratio = [](const GradCheckResult& r) {
    for (const auto& e : r.inputs)
      if (e.input == "poissons_ratio") return e;
    ADD_FAILURE() << "no poissons_ratio row";
    return GradCheckInput();
  };
  GradCheckOptions check;
  check.tangent = false;
  check.widen_below_margin = 1;  // only unresolved inputs are widened
  const GradCheckInput narrow = poissons_ratio(CheckRolloutGradient(scene, options, initial, 3, check));
  EXPECT_EQ(narrow.verdict, CheckVerdict::kPass);
  EXPECT_LT(narrow.margin, 10.0);
  check.widen_below_margin = GradCheckOptions().widen_below_margin;
  const GradCheckResult r = CheckRolloutGradient(scene, options, initial, 3, check);
  const GradCheckInput wide = poissons_ratio(r);
  EXPECT_EQ(wide.verdict, CheckVerdict::kPass) << GradCheckTable(r);
  EXPECT_EQ(wide.basis, "differences") << GradCheckTable(r);
  EXPECT_GE(wide.margin, 10.0) << GradCheckTable(r);
  EXPECT_GT(wide.step, narrow.step) << "a wider step decided";
}

// Semi-implicit Euler on calibrate-cantilever at its own step, 0.005 s:
// 5.8 x the stability limit at the initial state (8.6e-4 s), so the rollout
// grows without bound though three steps do not yet stop it. The check
// says so in its table and JSON; at 1e-4 s it does not.
TEST(GradCheckTest, ASemiImplicitCheckAboveTheStabilityLimitSaysItIsUnstable) {
  const SemiImplicitCase own = SemiImplicit("calibrate-cantilever");
  GradCheckOptions check;
  check.directions = 1;
  const GradCheckResult above = CheckRolloutGradient(own.scene, own.options, own.initial, 3, check);
  EXPECT_NEAR(above.explicit_stable_time_step, 8.6e-4, 0.1e-4);
  EXPECT_NE(GradCheckTable(above).find("# unstable: h = 0.005 s is 5.81 x semi-implicit Euler's stability limit at "
                                       "the initial state (0.00086 s): the rollout grows without bound"),
            std::string::npos)
      << GradCheckTable(above);
  EXPECT_EQ(GradCheckToJson(above)["explicit_stable_time_step"].get<double>(), above.explicit_stable_time_step);
  const SemiImplicitCase fine = SemiImplicit("calibrate-cantilever", 1e-4);
  const GradCheckResult below = CheckRolloutGradient(fine.scene, fine.options, fine.initial, 3, check);
  EXPECT_EQ(GradCheckTable(below).find("# unstable"), std::string::npos) << GradCheckTable(below);
  EXPECT_EQ(below.Count(CheckVerdict::kFail), 0) << GradCheckTable(below);
}

// The step the check recommends: semi-implicit Euler above half its
// stability limit (calibrate-cantilever's 0.005 s against 8.6e-4 s) is
// checked at half the limit, two digits rounded down, where the check
// passes every input and no longer says unstable; a step already below half
// the limit, and every implicit method, keep theirs.
TEST(GradCheckTest, SemiImplicitIsCheckedAtHalfItsStabilityLimitWhereTheProblemsStepIsAbove) {
  SemiImplicitCase c = SemiImplicit("calibrate-cantilever");
  Simulator sim(c.scene, c.options);
  const double limit = sim.ExplicitStableTimeStep(c.initial.x);
  const double h = RecommendedGradCheckTimeStep(c.scene, sim, c.initial);
  EXPECT_LE(h, 0.5 * limit);
  EXPECT_GE(h, 0.45 * limit);
  EXPECT_DOUBLE_EQ(h, 4.3e-4);
  c.options.time_step = h;
  GradCheckOptions check;
  check.directions = 1;
  const GradCheckResult r = CheckRolloutGradient(c.scene, c.options, c.initial, 3, check);
  EXPECT_EQ(GradCheckTable(r).find("# unstable"), std::string::npos) << GradCheckTable(r);
  EXPECT_EQ(r.verdict, CheckVerdict::kPass) << GradCheckTable(r);
  c.options.time_step = 1e-4;
  Simulator below(c.scene, c.options);
  EXPECT_EQ(RecommendedGradCheckTimeStep(c.scene, below, c.initial), 1e-4);
  c.options.time_step = 0.005;
  c.options.method = Method::kPdLbfgs;
  Simulator implicit(c.scene, c.options);
  EXPECT_EQ(RecommendedGradCheckTimeStep(c.scene, implicit, c.initial), 0.005);
}

// Semi-implicit Euler at h = 1e-4 s on starfish-control, which starts at
// rest in still water: over three tiny steps its faces move at about 1e-4
// m/s, and the check's force and velocity perturbations reverse some of
// them, where the force is continuous but not smooth (|u| u, the angle's
// jump). Differences across that kink cannot fail an input (the external
// forces' error of 1.9e-4 against a floor of 1.9e-5 with a second-order
// truncation estimate; the first-order one now gives 2.1e-4): an input they
// do not pass is unresolved with the reversing rollouts counted, and the
// tangent decides; near that kink the differences decide alone only with a
// margin of 10.
TEST(GradCheckTest, DifferencesAcrossAFacesZeroRelativeVelocityCannotFailAnInput) {
  const SemiImplicitCase c = SemiImplicit("starfish-control", 1e-4);
  const Scene& scene = c.scene;
  const SolverOptions& options = c.options;
  const State& initial = c.initial;
  GradCheckOptions check;
  check.tangent = false;
  check.concurrent_rollouts = 2;
  const GradCheckResult d = CheckRolloutGradient(scene, options, initial, 3, check);
  EXPECT_EQ(d.Count(CheckVerdict::kFail), 0) << GradCheckTable(d);
  int reversing = 0;
  for (const auto& e : d.inputs)
    reversing += e.verdict == CheckVerdict::kUnresolved &&
                 e.reason.find(
                     " perturbed rollouts reversed a wetted quad face's relative velocity (the force is "
                     "not smooth where it passes through zero); differences: ") != std::string::npos;
  EXPECT_GE(reversing, 1) << GradCheckTable(d);
  // With the tangent, differences near the kink decide alone only with a
  // margin of at least widen_below_margin (10); the tangent agrees with the
  // adjoint to rounding.
  check.tangent = true;
  const GradCheckResult t = CheckRolloutGradient(scene, options, initial, 3, check);
  EXPECT_EQ(t.verdict, CheckVerdict::kPass) << GradCheckTable(t);
  EXPECT_GE(t.min_margin, 10.0) << GradCheckTable(t);
  for (const auto& e : t.inputs) EXPECT_LE(e.tangent_error, 1e-12) << e.input;
}

// Plain pd limited to 2000 iterations per step does not reach rtol 1e-10 on the
// small beam (it stalls near 1e-7 relative): the check runs at the tightest
// of 1e-8, 1e-6 it reaches and says which, instead of stopping at the
// solver's error; with too few iterations for 1e-6 too the error stands.
TEST(GradCheckTest, AMethodThatCannotReachTheToleranceIsCheckedAtTheTightestItReaches) {
  SolverOptions options = CheckOptions(Method::kPd);
  options.rel_tolerance = 1e-10;
  options.max_iterations = 2000;
  const Scene scene = testing::SmallBeamScene();
  Simulator sim(scene, options);
  const State start = testing::MovingStart(sim);
  GradCheckOptions check;
  check.directions = 1;
  EXPECT_THROW(CheckRolloutGradient(scene, options, start, 3, check), SolverError);
  double used = 0;
  const GradCheckResult r = CheckRolloutGradientAtReachableTolerance(scene, options, start, 3, check, 1e-6, &used);
  EXPECT_NEAR(used, 1e-6, 1e-15) << "1e-8 needs more than 2000 iterations on this beam";
  EXPECT_EQ(r.Count(CheckVerdict::kFail), 0) << GradCheckTable(r);
  options.max_iterations = 3;
  EXPECT_THROW(CheckRolloutGradientAtReachableTolerance(scene, options, start, 3, check, 1e-6, &used), SolverError);
}

// Soft, nearly incompressible material crushed at a large step (the falling
// cube at E = 100 Pa, nu = 0.499, h = 0.1 s, as the stress grid has it): the
// implicit steps have more than one solution, and the Newton-Cholesky
// reference converges to another one, about 0.9 of the cube's size from
// pd-lbfgs's. Its gradient is another trajectory's, so it is not compared
// (reference_failure says so) and the check passes on the differences and
// the tangent; compared anyway, it would fail every input kind.
TEST(GradCheckTest, AReferenceOnAnotherSolutionOfTheImplicitStepsIsNotCompared) {
  const auto problem = MakeRefinedProblem("falling-cube", -6);
  Scene scene = problem->MakeScene();
  scene.material.youngs_modulus = 100;
  scene.material.poissons_ratio = 0.499;
  SolverOptions options = CheckOptions(Method::kPdLbfgs);
  options.time_step = 0.1;
  options.abs_tolerance = AutoAbsTolerance(scene, options.time_step);
  options.max_iterations = 20000;
  Simulator sim(scene, options);
  const State initial = problem->InitialState(sim);
  GradCheckOptions check;
  check.directions = 1;
  const GradCheckResult r = CheckRolloutGradient(scene, options, initial, 3, check);
  EXPECT_FALSE(r.reference);
  EXPECT_EQ(r.reference_failure.rfind("its trajectory is another solution of the implicit steps: a node ", 0), 0u)
      << r.reference_failure;
  EXPECT_EQ(r.verdict, CheckVerdict::kPass) << GradCheckTable(r);
  check.reference_trajectory_tolerance = 10;
  const GradCheckResult compared = CheckRolloutGradient(scene, options, initial, 3, check);
  EXPECT_TRUE(compared.reference);
  EXPECT_EQ(compared.verdict, CheckVerdict::kFail) << GradCheckTable(compared);
}

// A stiff cube in free fall (E = 1e10 Pa, nu = 0, h = 1e-3 s) with
// newton-pcg at rel_tolerance 1e-10: the loss's density derivative nearly
// cancels (gravity and inertia both scale with the density), so the forward's
// tolerance moves it by far more than 1e-4 relative from the converged
// Newton-Cholesky one, while the differences confirm the adjoint of the
// method's own rollout with a large margin. The method's gradient at
// rel_tolerance 1e-12 agrees with the reference: the input passes and the
// reason gives both errors. Failing it, as a plain comparison would, blames
// the adjoint for the forward's tolerance.
TEST(GradCheckTest, AReferenceDisagreementThatIsTheForwardsToleranceDoesNotFailADecisivePass) {
  const auto problem = MakeRefinedProblem("falling-cube", -6);
  Scene scene = problem->MakeScene();
  scene.material.youngs_modulus = 1e10;
  scene.material.poissons_ratio = 0;
  SolverOptions options = testing::TightOptions(Method::kNewtonPcg);
  options.time_step = 1e-3;
  options.rel_tolerance = 1e-10;
  options.backward_rel_tolerance = 1e-12;
  options.abs_tolerance = AutoAbsTolerance(scene, options.time_step);
  Simulator sim(scene, options);
  const State initial = problem->InitialState(sim);
  GradCheckOptions check;
  check.directions = 1;
  const GradCheckResult r = CheckRolloutGradient(scene, options, initial, 3, check);
  ASSERT_TRUE(r.reference) << r.reference_failure;
  EXPECT_EQ(r.verdict, CheckVerdict::kPass) << GradCheckTable(r);
  const auto density =
      std::find_if(r.inputs.begin(), r.inputs.end(), [](const GradCheckInput& e) { return e.input == "density"; });
  ASSERT_NE(density, r.inputs.end());
  EXPECT_GT(density->reference_error, 10 * r.tolerance) << GradCheckTable(r);
  EXPECT_LE(density->tightened_reference_error * 10, r.tolerance) << GradCheckTable(r);
  EXPECT_EQ(density->basis, "differences");
  EXPECT_GE(density->margin, check.decisive_margin);
  EXPECT_EQ(density->reason.rfind("differs from the Newton-Cholesky reference by ", 0), 0u) << density->reason;
  EXPECT_NE(density->reason.find(" at rel_tolerance 1e-12 (the forward's tolerance, not the adjoint)"),
            std::string::npos)
      << density->reason;
  // An input the reference agrees with needs no tighter rollout.
  for (const auto& e : r.inputs)
    if (e.reference_error <= r.tolerance) {
      EXPECT_TRUE(std::isnan(e.tightened_reference_error)) << e.input;
    }
}

TEST(GradCheckTest, TableJsonAndProgressReportTheResult) {
  GradCheckOptions check;
  check.directions = 1;
  std::vector<GradCheckProgress> progress;
  check.progress = [&](const GradCheckProgress& p) { progress.push_back(p); };
  const GradCheckResult r = Check(CheckOptions(Method::kNewtonCholesky), check);
  // One progress report per judged direction, in the result's order, with
  // its verdict and margin (one direction each here), the rollouts counting up.
  ASSERT_EQ(progress.size(), r.inputs.size());
  for (size_t i = 0; i < progress.size(); ++i) {
    EXPECT_EQ(progress[i].input, r.inputs[i].input);
    EXPECT_EQ(progress[i].direction, 1);
    EXPECT_EQ(progress[i].directions, 1);
    EXPECT_EQ(progress[i].verdict, r.inputs[i].verdict) << r.inputs[i].input;
    EXPECT_EQ(progress[i].margin, r.inputs[i].margin) << r.inputs[i].input;
    EXPECT_EQ(progress[i].basis, r.inputs[i].basis) << r.inputs[i].input;
    EXPECT_GT(progress[i].perturbed_rollouts, i == 0 ? 0 : progress[i - 1].perturbed_rollouts);
  }
  EXPECT_EQ(progress.back().perturbed_rollouts, r.perturbed_rollouts);
  const nlohmann::json j = GradCheckToJson(r);
  EXPECT_EQ(j.at("method"), "newton-cholesky");
  EXPECT_EQ(j.at("verdict"), "pass");
  EXPECT_EQ(j.at("pass").get<int>(), static_cast<int>(r.inputs.size()));
  EXPECT_EQ(j.at("unresolved").get<int>(), 0);
  EXPECT_DOUBLE_EQ(j.at("inputs").at("x0").at("error").get<double>(), r.inputs[0].error);
  EXPECT_TRUE(j.at("inputs").at("x0").at("reference_error").is_null());  // not compared
  EXPECT_DOUBLE_EQ(j.at("inputs").at("x0").at("tangent_error").get<double>(), r.inputs[0].tangent_error);
  EXPECT_EQ(j.at("inputs").at("x0").at("basis"), "differences");
  EXPECT_EQ(j.at("inputs").at("x0").at("tangent_directions").get<int>(), 0);
  EXPECT_EQ(j.at("tangent"), true);
  const std::string table = GradCheckTable(r);
  EXPECT_NE(table.find("youngs_modulus"), std::string::npos) << table;
  EXPECT_NE(table.find("# newton-cholesky: pass (tolerance 0.0001; 6 pass, 0 fail, 0 unresolved"), std::string::npos)
      << table;
}

// A clean check stops after three steps per direction, half the rollouts of
// all six, with the same verdict and a margin of at least early_stop_margin.
TEST(GradCheckTest, AResolvedDerivativeStopsAfterThreeStepsWithTheSameVerdict) {
  const SolverOptions options = CheckOptions(Method::kNewtonCholesky);
  const GradCheckResult early = Check(options);
  GradCheckOptions all_steps;
  all_steps.early_stop_margin = 0;
  const GradCheckResult full = Check(options, all_steps);
  ASSERT_EQ(early.verdict, CheckVerdict::kPass) << GradCheckTable(early);
  ASSERT_EQ(full.verdict, CheckVerdict::kPass) << GradCheckTable(full);
  EXPECT_GE(early.min_margin, GradCheckOptions().early_stop_margin);
  long directions = 0;
  for (const auto& e : early.inputs) directions += e.directions;
  EXPECT_EQ(early.perturbed_rollouts, 2 * 3 * directions);
  EXPECT_EQ(full.perturbed_rollouts, 2 * 6 * directions);
  ASSERT_EQ(early.inputs.size(), full.inputs.size());
  for (size_t i = 0; i < early.inputs.size(); ++i) {
    EXPECT_EQ(early.inputs[i].input, full.inputs[i].input);
    EXPECT_EQ(early.inputs[i].verdict, full.inputs[i].verdict) << early.inputs[i].input;
  }
}

// Running the perturbed rollouts three at once gives the same check: the
// same rollouts and verdicts, every input resolved with a margin of at least
// 10 as when they run one at a time (which thread runs which rollout changes
// only their rounding, so margins far above the tolerance are not compared
// exactly), with the plain steps and with the widened ones (h = 1e-5 s).
TEST(GradCheckTest, ConcurrentRolloutsGiveTheSameVerdicts) {
  for (const double h : {1e-2, 1e-5}) {
    SCOPED_TRACE("h = " + std::to_string(h));
    SolverOptions options = CheckOptions(Method::kPdLbfgs);
    options.time_step = h;
    options.num_threads = 1;
    GradCheckOptions one;
    one.directions = 1;
    GradCheckOptions three = one;
    three.concurrent_rollouts = 3;
    const GradCheckResult a = Check(options, one);
    const GradCheckResult b = Check(options, three);
    ASSERT_EQ(a.verdict, CheckVerdict::kPass) << GradCheckTable(a);
    EXPECT_EQ(b.verdict, CheckVerdict::kPass) << GradCheckTable(b);
    EXPECT_EQ(a.perturbed_rollouts, b.perturbed_rollouts);
    EXPECT_GE(a.min_margin, 10.0) << GradCheckTable(a);
    EXPECT_GE(b.min_margin, 10.0) << GradCheckTable(b);
    ASSERT_EQ(a.inputs.size(), b.inputs.size());
    bool widened = false;  // some input decided at a step above the largest of the six
    for (size_t i = 0; i < a.inputs.size(); ++i) {
      EXPECT_EQ(a.inputs[i].input, b.inputs[i].input);
      EXPECT_EQ(a.inputs[i].verdict, b.inputs[i].verdict) << a.inputs[i].input;
      widened = widened || a.inputs[i].step > one.largest_step;
    }
    if (h == 1e-5) {
      EXPECT_TRUE(widened) << GradCheckTable(a);
    }
  }
}

TEST(GradCheckTest, InvalidOptionsAreRefusedWithExactMessages) {
  GradCheckOptions o;
  o.directions = 0;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }), "directions = 0 is invalid: must be >= 1");
  o = GradCheckOptions();
  o.tolerance = -1;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }),
            "tolerance = -1 is invalid: must be finite and > 0");
  o = GradCheckOptions();
  o.step_count = 1;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }), "step_count = 1 is invalid: must be >= 2");
  o = GradCheckOptions();
  o.reference_rel_tolerance = 1;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }),
            "reference_rel_tolerance = 1 is invalid: must be in (0, 1)");
  o = GradCheckOptions();
  o.reference_trajectory_tolerance = 0;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }),
            "reference_trajectory_tolerance = 0 is invalid: must be finite and > 0");
  o = GradCheckOptions();
  o.early_stop_margin = 0.5;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }),
            "early_stop_margin = 0.5 is invalid: must be 0 or finite and >= 1");
  o = GradCheckOptions();
  o.widen_below_margin = 0.5;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }),
            "widen_below_margin = 0.5 is invalid: must be finite and >= 1");
  o = GradCheckOptions();
  o.decisive_margin = 0.5;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }),
            "decisive_margin = 0.5 is invalid: must be finite and >= 1");
  o = GradCheckOptions();
  o.concurrent_rollouts = 0;
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { o.Validate(); }),
            "concurrent_rollouts = 0 is invalid: must be in [1, " + std::to_string(MaxSolverThreads()) + "]");
}

}  // namespace
}  // namespace diffpd::problems
