// Tests of the Ipopt TNLP over a rollout function (rollout_nlp.h), called
// directly, without running Ipopt.
#include "diffpd/solvers/ipopt/rollout_nlp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "diffpd/error.h"
#include "diffpd/solvers/core/activation_block.h"
#include "solvers/core/non_finite_pull_back_block.h"
#include "solvers/ipopt/test_problems.h"
#include "util/expect_message.h"

namespace diffpd::testing {
namespace {

using solvers::RolloutNlp;

// Central difference of a scalar function of x along variable j.
template <typename Fn>
double CentralDifference(Fn&& fn, VectorXd x, int j, double eps) {
  const double x0 = x(j);
  x(j) = x0 + eps;
  const double plus = fn(x);
  x(j) = x0 - eps;
  const double minus = fn(x);
  return (plus - minus) / (2 * eps);
}

// A step per variable that suits its units (forces ~0.05 N, velocities
// ~0.05 m/s, positions ~1e-3 m, scaled material ~1).
VectorXd StepSizes(const BeamNlp& p) {
  VectorXd eps = VectorXd::Constant(p.nlp->num_variables(), 1e-5);
  eps.segment(p.position_offset, 6).setConstant(1e-6);
  return eps;
}

int ExpectedNonzeros(const BeamNlp& p) {
  const int n = p.nlp->num_variables();
  // Path constraint at state 2: per-step forces of steps 0 and 1, knots 0 and 1
  // of the piecewise-linear signal (knot 2 starts at step 3), and every
  // variable of the other blocks.
  const int path = 2 + 2 + (n - 8);
  return path + n + n + 2;
}

TEST(RolloutNlpTest, NlpInfoCountsVariablesConstraintsAndDeclaredNonzeros) {
  BeamNlp p(TightNewton());
  Ipopt::Index n, m, nnz_jac, nnz_h;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(p.nlp->get_nlp_info(n, m, nnz_jac, nnz_h, style));
  EXPECT_EQ(n, 11 + 3 + 6 + 2);
  EXPECT_EQ(m, 4);
  EXPECT_EQ(nnz_jac, ExpectedNonzeros(p));
  EXPECT_EQ(nnz_h, 0);
  EXPECT_EQ(style, Ipopt::TNLP::C_STYLE);
}

TEST(RolloutNlpTest, BoundsAndStartingPointComeFromTheBlocksAndConstraints) {
  BeamNlp p(TightNewton());
  const int n = p.nlp->num_variables(), m = p.nlp->num_constraints();
  std::vector<double> xl(n), xu(n), gl(m), gu(m), x(n);
  ASSERT_TRUE(p.nlp->get_bounds_info(n, xl.data(), xu.data(), m, gl.data(), gu.data()));
  EXPECT_EQ(xl[p.force_offset], -0.5);
  EXPECT_EQ(xu[p.force_offset + 9], 0.5);
  EXPECT_EQ(xu[p.force_offset + 10], M_PI);  // the sinusoid's phase
  EXPECT_LE(xl[p.velocity_offset], -1e19);   // unbounded: beyond Ipopt's infinity
  EXPECT_GE(xu[p.velocity_offset], 1e19);
  EXPECT_EQ(xl[p.material_offset], 0.5);
  EXPECT_EQ(xu[p.material_offset + 1], 5.0);
  EXPECT_EQ(gl[0], -1.0);
  EXPECT_EQ(gu[2], 0.1);
  EXPECT_LE(gl[3], -1e19);
  EXPECT_EQ(gu[3], 1.0);
  ASSERT_TRUE(p.nlp->get_starting_point(n, true, x.data(), false, nullptr, nullptr, m, false, nullptr));
  EXPECT_EQ(x[p.force_offset + 10], 0.7);
  EXPECT_EQ(x[p.velocity_offset + 2], 0.05);
  EXPECT_EQ(x[p.material_offset], 2.0);  // E = 2e5 Pa at scale 1e5
  EXPECT_EQ(x[p.material_offset + 1], 1.0);
  // Multipliers cannot be warm-started.
  EXPECT_FALSE(p.nlp->get_starting_point(n, true, x.data(), true, x.data(), x.data(), m, false, nullptr));
  std::vector<Ipopt::TNLP::LinearityType> kinds(m);
  ASSERT_TRUE(p.nlp->get_constraints_linearity(m, kinds.data()));
  EXPECT_EQ(kinds[0], Ipopt::TNLP::NON_LINEAR);
  EXPECT_EQ(kinds[3], Ipopt::TNLP::LINEAR);
}

TEST(RolloutNlpTest, JacobianStructureListsRowsInOrderAndOmitsLaterPerStepControlsOfPathConstraints) {
  BeamNlp p(TightNewton());
  Ipopt::Index n, m, nnz, nnz_h;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(p.nlp->get_nlp_info(n, m, nnz, nnz_h, style));
  std::vector<Ipopt::Index> rows(nnz), cols(nnz);
  ASSERT_TRUE(p.nlp->eval_jac_g(n, nullptr, true, m, nnz, rows.data(), cols.data(), nullptr));
  std::vector<std::vector<int>> per_row(m);
  for (int k = 0; k < nnz; ++k) {
    ASSERT_GE(rows[k], 0);
    ASSERT_LT(rows[k], m);
    if (k > 0) {
      ASSERT_GE(rows[k], rows[k - 1]);
    }
    per_row[rows[k]].push_back(cols[k]);
  }
  // Path row: per-step forces 0, 1 (not 2..4), knots 0, 1 (not 2).
  auto has = [&](int r, int c) { return std::find(per_row[r].begin(), per_row[r].end(), c) != per_row[r].end(); };
  EXPECT_TRUE(has(0, p.force_offset + 0));
  EXPECT_TRUE(has(0, p.force_offset + 1));
  for (int s = 2; s < 5; ++s) EXPECT_FALSE(has(0, p.force_offset + s)) << "step " << s;
  EXPECT_TRUE(has(0, p.force_offset + 6));
  EXPECT_FALSE(has(0, p.force_offset + 7));
  EXPECT_EQ(per_row[1].size(), size_t(n));
  EXPECT_EQ(per_row[3], (std::vector<int>{p.force_offset + 0, p.force_offset + 6}));
  // A wrong element count is refused.
  EXPECT_FALSE(p.nlp->eval_jac_g(n, nullptr, true, m, nnz + 1, rows.data(), cols.data(), nullptr));
}

TEST(RolloutNlpTest, ObjectiveGradientMatchesCentralDifferencesNewton) {
  BeamNlp p(TightNewton());
  const VectorXd x = p.nlp->starting_point();
  const int n = p.nlp->num_variables();
  std::vector<double> grad(n);
  ASSERT_TRUE(p.nlp->eval_grad_f(n, x.data(), true, grad.data()));
  const VectorXd eps = StepSizes(p);
  auto f = [&](const VectorXd& y) {
    double v = 0;
    EXPECT_TRUE(p.nlp->eval_f(n, y.data(), true, v));
    return v;
  };
  const double scale = Eigen::Map<VectorXd>(grad.data(), n).cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  for (int j = 0; j < n; ++j) {
    const double fd = CentralDifference(f, x, j, eps(j));
    EXPECT_NEAR(grad[j], fd, 1e-6 * std::max(std::abs(fd), 1e-2 * scale)) << "variable " << j;
  }
}

TEST(RolloutNlpTest, ConstraintJacobianMatchesCentralDifferencesNewton) {
  BeamNlp p(TightNewton());
  const VectorXd x = p.nlp->starting_point();
  const int n = p.nlp->num_variables(), m = p.nlp->num_constraints();
  MatrixXd jac;
  ASSERT_TRUE(p.nlp->ConstraintJacobian(x, &jac));
  const VectorXd eps = StepSizes(p);
  MatrixXd fd(m, n);
  for (int j = 0; j < n; ++j) {
    VectorXd plus = x, minus = x, g_plus, g_minus;
    plus(j) += eps(j);
    minus(j) -= eps(j);
    ASSERT_TRUE(p.nlp->Constraints(plus, &g_plus));
    ASSERT_TRUE(p.nlp->Constraints(minus, &g_minus));
    fd.col(j) = (g_plus - g_minus) / (2 * eps(j));
  }
  for (int r = 0; r < m; ++r) {
    const double scale = jac.row(r).cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0) << "row " << r;
    for (int j = 0; j < n; ++j)
      EXPECT_NEAR(jac(r, j), fd(r, j), 1e-6 * std::max(std::abs(fd(r, j)), 1e-2 * scale))
          << "row " << r << " variable " << j;
  }
  // Declared zeros are true zeros: the path constraint at state 2 does not
  // move when the forces of steps 2..4 do (up to the last bits of the
  // solves), while it does move with the force of step 1.
  const double live = std::abs(fd(0, p.force_offset + 1));
  ASSERT_GT(live, 1e-3);
  for (int s = 2; s < 5; ++s) EXPECT_LE(std::abs(fd(0, p.force_offset + s)), 1e-9 * live) << "step " << s;
}

TEST(RolloutNlpTest, ValuesCallOfEvalJacGFillsTheDeclaredEntries) {
  BeamNlp p(TightNewton());
  const VectorXd x = p.nlp->starting_point();
  Ipopt::Index n, m, nnz, nnz_h;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(p.nlp->get_nlp_info(n, m, nnz, nnz_h, style));
  std::vector<Ipopt::Index> rows(nnz), cols(nnz);
  std::vector<double> values(nnz);
  ASSERT_TRUE(p.nlp->eval_jac_g(n, nullptr, true, m, nnz, rows.data(), cols.data(), nullptr));
  ASSERT_TRUE(p.nlp->eval_jac_g(n, x.data(), true, m, nnz, nullptr, nullptr, values.data()));
  MatrixXd dense;
  ASSERT_TRUE(p.nlp->ConstraintJacobian(x, &dense));
  for (int k = 0; k < nnz; ++k) EXPECT_EQ(values[k], dense(rows[k], cols[k]));
  EXPECT_EQ(values[nnz - 2], 1.0);  // the linear row's coefficients
  EXPECT_EQ(values[nnz - 1], -2.0);
}

TEST(RolloutNlpTest, ObjectiveGradientMatchesADirectionalCentralDifferencePd) {
  SolverOptions options = TightPd();
  options.abs_tolerance = 1e-10;
  BeamNlp p(options);
  const VectorXd x = p.nlp->starting_point();
  VectorXd grad;
  ASSERT_TRUE(p.nlp->ObjectiveGradient(x, &grad));
  // A fixed direction mixing every block, scaled to each variable's units.
  VectorXd d = StepSizes(p) * 1e5;
  for (int j = 0; j < d.size(); ++j) d(j) *= (j % 3 == 0 ? 1.0 : j % 3 == 1 ? -0.5 : 0.25);
  const double eps = 1e-5;
  double plus, minus;
  ASSERT_TRUE(p.nlp->Objective(x + eps * d, &plus));
  ASSERT_TRUE(p.nlp->Objective(x - eps * d, &minus));
  const double fd = (plus - minus) / (2 * eps);
  EXPECT_NEAR(grad.dot(d), fd, 1e-6 * std::abs(fd));
}

TEST(RolloutNlpTest, OneRolloutPerEvaluationPoint) {
  BeamNlp p(TightNewton());
  VectorXd x = p.nlp->starting_point();
  const int n = p.nlp->num_variables(), m = p.nlp->num_constraints();
  Ipopt::Index nnz, nnz_h;
  Ipopt::TNLP::IndexStyleEnum style;
  Ipopt::Index nn, mm;
  ASSERT_TRUE(p.nlp->get_nlp_info(nn, mm, nnz, nnz_h, style));
  double f;
  std::vector<double> grad(n), g(m), jac(nnz);
  ASSERT_TRUE(p.nlp->eval_f(n, x.data(), true, f));
  ASSERT_TRUE(p.nlp->eval_grad_f(n, x.data(), false, grad.data()));
  ASSERT_TRUE(p.nlp->eval_g(n, x.data(), false, m, g.data()));
  ASSERT_TRUE(p.nlp->eval_jac_g(n, x.data(), false, m, nnz, nullptr, nullptr, jac.data()));
  EXPECT_EQ(p.nlp->statistics().rollouts, 1);
  // 1 adjoint for the objective, 1 per trajectory constraint.
  EXPECT_EQ(p.nlp->statistics().adjoint_passes, 1 + 3);
  // Repeating an evaluation at the same point costs nothing.
  ASSERT_TRUE(p.nlp->eval_grad_f(n, x.data(), false, grad.data()));
  ASSERT_TRUE(p.nlp->eval_f(n, x.data(), true, f));
  EXPECT_EQ(p.nlp->statistics().rollouts, 1);
  EXPECT_EQ(p.nlp->statistics().adjoint_passes, 4);
  // A new point simulates once more, whatever new_x says.
  x(0) += 1e-3;
  ASSERT_TRUE(p.nlp->eval_g(n, x.data(), false, m, g.data()));
  ASSERT_TRUE(p.nlp->eval_f(n, x.data(), false, f));
  EXPECT_EQ(p.nlp->statistics().rollouts, 2);
  EXPECT_GT(p.nlp->statistics().forward_seconds, 0);
  EXPECT_GT(p.nlp->statistics().backward_seconds, 0);
}

TEST(RolloutNlpTest, FailedRolloutMakesEveryEvaluationReturnFalseAndRecovers) {
  // PD with at most 3 iterations per step: the rest state converges at once
  // (zero residual, no gravity), a large tip force does not.
  Scene scene = SmallBeamScene();
  scene.gravity.reset();
  SolverOptions options = TightPd();
  options.max_iterations = 3;
  const std::vector<int> tip = NodesAtXMax(scene.mesh);
  RolloutNlp nlp(std::make_unique<solvers::RolloutFunction>(scene, options, 3));
  std::vector<solvers::ExternalForceBlock::Channel> channels(1);
  channels[0] = {tip, Vec3::UnitZ(), std::make_unique<solvers::PerStepSignal>(3)};
  nlp.AddVariables(std::make_unique<solvers::ExternalForceBlock>(std::move(channels)));
  const int n3 = scene.mesh.num_vertices();
  nlp.AddObjective(
      std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(n3, tip[0]), solvers::kFinalState, Vec3::UnitZ()));
  nlp.AddConstraint(std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(n3, tip[0]), 1, Vec3::UnitZ()), -1,
                    1);
  const int n = nlp.num_variables(), m = nlp.num_constraints();
  Ipopt::Index nn, mm, nnz, nnz_h;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(nlp.get_nlp_info(nn, mm, nnz, nnz_h, style));
  double f;
  std::vector<double> grad(n), g(m), jac(nnz);
  const VectorXd bad = VectorXd::Constant(n, 5.0);  // 5 N per node
  EXPECT_FALSE(nlp.eval_f(n, bad.data(), true, f));
  EXPECT_FALSE(nlp.eval_grad_f(n, bad.data(), false, grad.data()));
  EXPECT_FALSE(nlp.eval_g(n, bad.data(), false, m, g.data()));
  EXPECT_FALSE(nlp.eval_jac_g(n, bad.data(), false, m, nnz, nullptr, nullptr, jac.data()));
  EXPECT_EQ(nlp.statistics().rollouts, 1);
  EXPECT_EQ(nlp.statistics().failed_rollouts, 1);
  EXPECT_EQ(nlp.last_error().rfind("rollout failed (maximum number of iterations reached): ", 0), 0u)
      << nlp.last_error();
  EXPECT_TRUE(std::isinf(nlp.ConstraintViolation(bad)));
  const VectorXd good = VectorXd::Zero(n);
  EXPECT_TRUE(nlp.eval_f(n, good.data(), true, f));
  EXPECT_TRUE(nlp.eval_jac_g(n, good.data(), false, m, nnz, nullptr, nullptr, jac.data()));
}

TEST(RolloutNlpTest, ANonFiniteGradientOrJacobianIsAFailedEvaluation) {
  // A material block whose reverse-mode derivative is NaN: the values are
  // fine, every derivative evaluation returns false instead of passing NaN on.
  Scene scene = SmallBeamScene();
  RolloutNlp nlp(std::make_unique<solvers::RolloutFunction>(scene, TightOptions(Method::kNewtonCholesky), 3));
  nlp.AddVariables(std::make_unique<NonFinitePullBackBlock>(std::make_unique<solvers::MaterialBlock>(
      std::vector<solvers::MaterialBlock::Entry>{solvers::MaterialField::kYoungsModulus}, scene)));
  const int n3 = scene.mesh.num_vertices();
  nlp.AddObjective(
      std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(n3, n3 - 1), solvers::kFinalState, Vec3::UnitZ()));
  nlp.AddConstraint(std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(n3, n3 - 1), 2, Vec3::UnitZ()), -1,
                    1);
  const int n = nlp.num_variables(), m = nlp.num_constraints();
  Ipopt::Index nn, mm, nnz, nnz_h;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(nlp.get_nlp_info(nn, mm, nnz, nnz_h, style));
  const VectorXd x = VectorXd::Constant(n, 2e5);
  double f;
  std::vector<double> grad(n, 0.0), g(m), jac(nnz, 0.0);
  EXPECT_TRUE(nlp.eval_f(n, x.data(), true, f));
  EXPECT_TRUE(std::isfinite(f));
  EXPECT_TRUE(nlp.eval_g(n, x.data(), false, m, g.data()));
  EXPECT_FALSE(nlp.eval_grad_f(n, x.data(), false, grad.data()));
  EXPECT_EQ(nlp.last_error(),
            "gradient failed (non-finite value): the derivative with respect to parameter 0 = nan is not finite");
  EXPECT_FALSE(nlp.eval_jac_g(n, x.data(), false, m, nnz, nullptr, nullptr, jac.data()));
  EXPECT_EQ(nlp.last_error().rfind("Jacobian failed (non-finite value): row ", 0), 0u) << nlp.last_error();
}

TEST(RolloutNlpTest, ConstraintViolationIsTheLargestBoundOrConstraintExcess) {
  BeamNlp p(TightNewton());
  VectorXd x = p.nlp->starting_point();
  VectorXd g;
  ASSERT_TRUE(p.nlp->Constraints(x, &g));
  EXPECT_EQ(p.nlp->ConstraintViolation(x), std::max(0.0, std::abs(g(2)) - 0.1));
  x(p.force_offset + 3) = 0.75;  // bound 0.5
  ASSERT_TRUE(p.nlp->Constraints(x, &g));
  EXPECT_NEAR(p.nlp->ConstraintViolation(x), std::max(0.25, std::abs(g(2)) - 0.1), 1e-15);
}

TEST(RolloutNlpTest, ForwardModeJacobianEqualsReverseMode) {
  BeamNlp p(TightNewton());
  const VectorXd x = p.nlp->starting_point();
  ASSERT_TRUE(p.nlp->ForwardModeAvailable());
  EXPECT_EQ(p.nlp->ResolvedJacobianMode(), solvers::DerivativeMode::kReverse);  // 22 variables, 3 constraints
  MatrixXd reverse, forward;
  p.nlp->SetJacobianMode(solvers::DerivativeMode::kReverse);
  ASSERT_TRUE(p.nlp->ConstraintJacobian(x, &reverse));
  EXPECT_EQ(p.nlp->statistics().tangent_passes, 0);
  // A fresh NLP, so that nothing is cached.
  BeamNlp q(TightNewton());
  q.nlp->SetJacobianMode(solvers::DerivativeMode::kForward);
  ASSERT_TRUE(q.nlp->ConstraintJacobian(x, &forward)) << q.nlp->last_error();
  EXPECT_EQ(q.nlp->statistics().tangent_passes, 1);
  EXPECT_EQ(q.nlp->statistics().adjoint_passes, 0);
  for (int r = 0; r < reverse.rows(); ++r)
    for (int j = 0; j < reverse.cols(); ++j)
      EXPECT_NEAR(forward(r, j), reverse(r, j), 1e-9 * reverse.row(r).cwiseAbs().maxCoeff()) << r << ", " << j;
}

TEST(RolloutNlpTest, AutoModeChoosesForwardForFewVariablesAndManyConstraints) {
  // 3 variables (the tip's initial velocity), 4 path constraints.
  auto make = [] {
    const Scene scene = SmallBeamScene();
    const std::vector<int> tip = NodesAtXMax(scene.mesh);
    Ipopt::SmartPtr<RolloutNlp> nlp = EmptyNlp(scene, TightNewton(), 4);
    nlp->AddVariables(std::make_unique<solvers::InitialStateBlock>(solvers::InitialStateBlock::kVelocity, tip));
    const int n = scene.mesh.num_vertices();
    for (int k = 1; k <= 4; ++k)
      nlp->AddConstraint(std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(n, tip[0]), k, Vec3::UnitZ()),
                         -1, 1);
    return nlp;
  };
  Ipopt::SmartPtr<RolloutNlp> automatic = make(), reverse = make();
  reverse->SetJacobianMode(solvers::DerivativeMode::kReverse);
  EXPECT_EQ(automatic->ResolvedJacobianMode(), solvers::DerivativeMode::kForward);
  const VectorXd x = VectorXd::Constant(3, 0.01);
  MatrixXd jac_auto, jac_reverse;
  ASSERT_TRUE(automatic->ConstraintJacobian(x, &jac_auto));
  ASSERT_TRUE(reverse->ConstraintJacobian(x, &jac_reverse));
  EXPECT_EQ(automatic->statistics().tangent_passes, 1);
  EXPECT_EQ(automatic->statistics().adjoint_passes, 0);
  EXPECT_EQ(reverse->statistics().adjoint_passes, 4);
  EXPECT_LE((jac_auto - jac_reverse).cwiseAbs().maxCoeff(), 1e-10 * jac_reverse.cwiseAbs().maxCoeff());
  EXPECT_GT(jac_auto(3, 2), jac_auto(0, 2));  // a z velocity lifts the tip more the longer it acts
}

// The beam with two muscles (upper and lower half of the elements, fibres
// along x) driven by activations: one per-step channel, one Fourier channel.
struct MuscleBeam {
  static constexpr int kSteps = 4;
  Ipopt::SmartPtr<RolloutNlp> nlp;

  MuscleBeam() {
    Scene scene = SmallBeamScene();
    Muscle upper, lower;
    for (int e = 0; e < scene.mesh.num_elements(); ++e) {
      double z = 0;
      for (int a = 0; a < 8; ++a) z += scene.mesh.vertices(2, scene.mesh.elements(a, e)) / 8;
      (z > 0.02 ? upper : lower).elements.push_back(e);
    }
    upper.fibers = lower.fibers = {Vec3::UnitX()};
    upper.stiffness = lower.stiffness = 1e5;
    scene.muscles = {upper, lower};
    nlp = EmptyNlp(scene, TightNewton(), kSteps);
    std::vector<solvers::ActivationBlock::Channel> channels(2);
    channels[0] = {0, std::make_unique<solvers::PerStepSignal>(kSteps)};
    channels[1] = {1, std::make_unique<solvers::FourierSignal>(kSteps, 0.01, 0.04, 1)};
    auto activation = std::make_unique<solvers::ActivationBlock>(std::move(channels));
    VectorXd a0(7);
    a0 << 0.9, 0.95, 1.0, 0.85, 1.0, 0.05, -0.03;
    activation->SetInitial(a0);
    nlp->AddVariables(std::move(activation));
    const std::vector<int> tip = NodesAtXMax(scene.mesh);
    const int n = scene.mesh.num_vertices();
    const VectorXd rest = nlp->function().base().initial.x;
    nlp->AddObjective(std::make_unique<solvers::PointDistanceSquared>(
        solvers::MeanOf(n, tip), solvers::kFinalState, solvers::MeanOf(n, tip).At(rest) - Vec3(0.01, 0, 0.01)));
    nlp->AddConstraint(std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(n, tip[0]), 2, Vec3::UnitX()), -1,
                       1);
  }
};

TEST(RolloutNlpTest, ActivationGradientAndJacobianMatchCentralDifferences) {
  MuscleBeam p;
  // Forward mode covers activations; with 7 variables and 1 constraint the
  // Jacobian is by reverse mode.
  EXPECT_TRUE(p.nlp->ForwardModeAvailable());
  EXPECT_EQ(p.nlp->ResolvedJacobianMode(), solvers::DerivativeMode::kReverse);
  const VectorXd x = p.nlp->starting_point();
  VectorXd grad;
  MatrixXd jac;
  ASSERT_TRUE(p.nlp->ObjectiveGradient(x, &grad)) << p.nlp->last_error();
  ASSERT_TRUE(p.nlp->ConstraintJacobian(x, &jac));
  ASSERT_GT(grad.cwiseAbs().maxCoeff(), 0);
  const double eps = 1e-5;
  for (int j = 0; j < x.size(); ++j) {
    VectorXd plus = x, minus = x;
    plus(j) += eps;
    minus(j) -= eps;
    double fp, fm;
    VectorXd gp, gm;
    ASSERT_TRUE(p.nlp->Objective(plus, &fp));
    ASSERT_TRUE(p.nlp->Constraints(plus, &gp));
    ASSERT_TRUE(p.nlp->Objective(minus, &fm));
    ASSERT_TRUE(p.nlp->Constraints(minus, &gm));
    const double fd = (fp - fm) / (2 * eps), fd_g = (gp(0) - gm(0)) / (2 * eps);
    EXPECT_NEAR(grad(j), fd, 1e-6 * std::max(std::abs(fd), 1e-2 * grad.cwiseAbs().maxCoeff())) << "variable " << j;
    EXPECT_NEAR(jac(0, j), fd_g, 1e-6 * std::max(std::abs(fd_g), 1e-2 * jac.cwiseAbs().maxCoeff())) << "variable " << j;
  }
  // The path constraint at state 2 has no entry for the per-step activations
  // of steps 2 and 3.
  EXPECT_EQ(jac(0, 2), 0.0);
  EXPECT_EQ(jac(0, 3), 0.0);
  // Forward mode (tangents along activations) gives the same Jacobian.
  MuscleBeam q;
  q.nlp->SetJacobianMode(solvers::DerivativeMode::kForward);
  MatrixXd forward;
  ASSERT_TRUE(q.nlp->ConstraintJacobian(x, &forward)) << q.nlp->last_error();
  EXPECT_EQ(q.nlp->statistics().tangent_passes, 1);
  EXPECT_LE((forward - jac).cwiseAbs().maxCoeff(), 1e-9 * jac.cwiseAbs().maxCoeff());
}

TEST(RolloutNlpTest, KeepsTheBestFeasiblePointWhereBothFAndGWereEvaluated) {
  // A free cube thrown with velocity v (|v_i| <= 1): objective -c_z(K), the
  // constraint c_x(K) - c_x(0) <= 0 (c the centre of mass).
  Scene scene;
  scene.mesh = BoxHexMesh(2, 2, 2, 0.1, 0.1, 0.1);
  scene.gravity = Vec3(0, 0, -9.81);
  SolverOptions options = TightNewton();
  options.abs_tolerance = 1e-9;
  options.rel_tolerance = 1e-9;
  std::vector<int> all(scene.mesh.num_vertices());
  for (int i = 0; i < scene.mesh.num_vertices(); ++i) all[i] = i;
  RolloutNlp nlp(std::make_unique<solvers::RolloutFunction>(scene, options, 3));
  auto v0 = std::make_unique<solvers::InitialStateBlock>(solvers::InitialStateBlock::kVelocity, all);
  v0->SetBounds(-1.0, 1.0);
  nlp.AddVariables(std::move(v0));
  const solvers::TrackedPoint com = solvers::CentreOfMass(nlp.function().simulator().LumpedMass());
  nlp.AddObjective(std::make_unique<solvers::PointCoordinate>(com, solvers::kFinalState, Vec3::UnitZ()), -1.0);
  nlp.AddConstraint(std::make_unique<solvers::PointTravel>(com, 0, solvers::kFinalState, Vec3::UnitX()), -1.0, 0.0);
  nlp.ResetBestFeasible(1e-6);
  EXPECT_FALSE(nlp.has_best_feasible());
  const VectorXd x0 = VectorXd::Zero(3), x1 = Vec3(0.5, 0, 0.5), x2 = Vec3(-0.5, 0, 0.5), x3 = Vec3(0, 0, 1.5);
  double f0, f1, f2, f3;
  VectorXd g;
  ASSERT_TRUE(nlp.Objective(x0, &f0)) << nlp.last_error();
  EXPECT_FALSE(nlp.has_best_feasible());  // g not evaluated there yet
  ASSERT_TRUE(nlp.Constraints(x0, &g));
  ASSERT_TRUE(nlp.has_best_feasible());
  EXPECT_EQ(nlp.best_feasible_x(), x0);
  EXPECT_EQ(nlp.best_feasible_objective(), f0);
  // Lower objective, but c_x(K) > 0: not kept.
  ASSERT_TRUE(nlp.Constraints(x1, &g));
  ASSERT_TRUE(nlp.Objective(x1, &f1));
  ASSERT_LT(f1, f0);
  ASSERT_GT(g(0), 0.0);
  EXPECT_EQ(nlp.best_feasible_x(), x0);
  // Lower objective outside the variable bounds: not kept either.
  ASSERT_TRUE(nlp.Objective(x3, &f3));
  ASSERT_TRUE(nlp.Constraints(x3, &g));
  ASSERT_LT(f3, f0);
  EXPECT_EQ(nlp.best_feasible_x(), x0);
  // The same height, feasible: kept.
  ASSERT_TRUE(nlp.Objective(x2, &f2));
  ASSERT_TRUE(nlp.Constraints(x2, &g));
  EXPECT_NEAR(f2, f1, 1e-12);
  EXPECT_EQ(nlp.best_feasible_x(), x2);
  EXPECT_EQ(nlp.best_feasible_objective(), f2);
}

TEST(RolloutNlpTest, BadInputIsRefusedWithAMessage) {
  EXPECT_EQ(MessageOf<InvalidInputError>([] { RolloutNlp nlp(nullptr); }), "RolloutNlp: the rollout function is null");
  Ipopt::SmartPtr<RolloutNlp> nlp = EmptyNlp(SmallBeamScene(), TightNewton(), 4);
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              nlp->AddVariables(std::make_unique<solvers::InitialStateBlock>(solvers::InitialStateBlock::kVelocity,
                                                                             std::vector<int>{1000}));
            }),
            "initial_velocity: node 1000 is out of range: the mesh has 45 nodes");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              nlp->AddConstraint(
                  std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(45, 0), 7, Vec3::UnitZ(), "late"), 0,
                  1);
            }),
            "functional 'late' reads state 7, outside the rollout's states [0, 4]");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              nlp->AddConstraint(
                  std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(45, 0), 1, Vec3::UnitZ(), "c"), 1, 0);
            }),
            "RolloutNlp: constraint 'c' bounds [1, 0] are invalid: need lower <= upper, no NaN");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { nlp->AddObjectiveRows({3}); }),
            "RolloutNlp: objective row 3 is out of range [0, 0)");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { nlp->AddRegularization(0, 2, 1.0); }),
            "RolloutNlp: regularization of variables [0, 2) with weight 1 is invalid: need a range inside [0, 0) and a "
            "finite weight >= 0 and reference");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { nlp->SetStartingPoint(VectorXd::Zero(2)); }),
            "RolloutNlp: the starting point has 2 entries, expected 0 finite values");
}

}  // namespace
}  // namespace diffpd::testing
