// Tests of SolveWithIpopt (ipopt_solve.h): Ipopt's derivative checker on the
// adapter, a constrained solve, infeasibility, option pass-through and
// failed rollouts inside a solve.
#include "diffpd/solvers/ipopt/ipopt_solve.h"

#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "solvers/ipopt/test_problems.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

IpoptOptions DerivativeTestOptions() {
  IpoptOptions o;
  o.string_options = {{"derivative_test", "first-order"}};
  o.int_options = {{"max_iter", 0}};
  // Check at the starting point itself (Ipopt's default moves it randomly by
  // up to 10 units, far outside where these instances are meant to live).
  o.num_options = {{"derivative_test_perturbation", 1e-6}, {"point_perturbation_radius", 0.0}};
  return o;
}

TEST(IpoptSolveTest, DerivativeCheckerReportsNoErrorOnTheAdapter) {
  BeamNlp p(TightNewton());
  const IpoptSummary s = SolveWithIpopt(p.nlp, DerivativeTestOptions());
  EXPECT_NE(s.log.find("Starting derivative checker for first derivatives."), std::string::npos) << s.log;
  EXPECT_EQ(s.derivative_checker_errors, 0) << s.log;
}

// An objective term whose gradient is deliberately twice too large.
class WrongGradient : public TrajectoryFunction {
 public:
  explicit WrongGradient(TrackedPoint p) : f_(std::move(p), kFinalState, Vec3::UnitZ()) {}
  std::string name() const override { return "wrong"; }
  int LastState(int num_steps) const override { return num_steps; }
  double Value(const Rollout& r) const override { return f_.Value(r); }
  void AddGradient(const Rollout& r, double w, LossGradient* loss) const override { f_.AddGradient(r, 2 * w, loss); }

 private:
  PointCoordinate f_;
};

TEST(IpoptSolveTest, DerivativeCheckerCatchesAWrongGradient) {
  BeamNlp p(TightNewton());
  p.nlp->AddObjective(std::make_unique<WrongGradient>(NodePoint(p.sim->num_dofs() / 3, p.tip[0])), 10.0);
  const IpoptSummary s = SolveWithIpopt(p.nlp, DerivativeTestOptions());
  EXPECT_GT(s.derivative_checker_errors, 0) << s.log;
}

// The beam's tip is steered by forces (piecewise linear in time, 4 knots
// per axis, |f| <= 0.2 N per node) to a target 1.5 cm above and 5 mm beside
// its rest position at K = 8, while at state 4 it may rise at most 3 mm.
struct SteerBeam {
  static constexpr int kSteps = 8;
  Ipopt::SmartPtr<RolloutNlp> nlp;
  double path_limit = 0;

  explicit SteerBeam(const SolverOptions& options) {
    const Scene scene = SmallBeamScene();
    const Mesh& mesh = scene.mesh;
    const std::vector<int> tip = NodesAtXMax(mesh);
    nlp = EmptyNlp(scene, options, kSteps);
    std::vector<ExternalForceBlock::Channel> channels(2);
    channels[0] = {tip, Vec3::UnitZ(), std::make_unique<PiecewiseLinearSignal>(kSteps, 4)};
    channels[1] = {tip, Vec3::UnitY(), std::make_unique<PiecewiseLinearSignal>(kSteps, 4)};
    auto forces = std::make_unique<ExternalForceBlock>(std::move(channels));
    forces->SetBounds(-0.2, 0.2);
    const int offset = nlp->AddVariables(std::move(forces));
    const int n = mesh.num_vertices();
    const TrackedPoint marker = NodePoint(n, tip.back());
    const Vec3 rest = marker.At(nlp->function().base().initial.x);
    nlp->AddObjective(std::make_unique<PointDistanceSquared>(marker, kFinalState, rest + Vec3(0, 0.005, 0.015)), 1e4);
    nlp->AddRegularization(offset, 8, 1e-3);
    path_limit = rest.z() + 0.003;
    nlp->AddConstraint(std::make_unique<PointCoordinate>(marker, 4, Vec3::UnitZ(), "tip_z_at_4"), -1.0, path_limit);
  }
};

// Newton-Cholesky at ordinary tolerances (no finite differences here).
SolverOptions OrdinaryNewton() {
  SolverOptions o = TightNewton();
  o.abs_tolerance = 1e-9;
  o.rel_tolerance = 1e-8;
  return o;
}

TEST(IpoptSolveTest, SmallInstanceReachesAFeasiblePointWithAMuchLowerObjective) {
  SteerBeam p(OrdinaryNewton());
  IpoptOptions o;
  o.num_options = {{"tol", 1e-7}};
  o.int_options = {{"max_iter", 100}};
  const IpoptSummary s = SolveWithIpopt(p.nlp, o);
  ASSERT_TRUE(s.succeeded()) << s.BriefReport() << "\n" << s.log;
  EXPECT_LE(s.constraint_violation, 1e-6) << s.BriefReport();
  // Stated margin: the objective drops by at least 90 % from the rest start.
  EXPECT_LE(s.objective, 0.1 * s.initial_objective) << s.BriefReport();
  VectorXd g;
  ASSERT_TRUE(p.nlp->Constraints(s.x, &g));
  EXPECT_LE(g(0), p.path_limit + 1e-6);
  EXPECT_GE(s.evaluations, s.iterations);
  EXPECT_EQ(s.objective_history.size(), size_t(s.iterations + 1));
  EXPECT_NEAR(s.objective_history.front(), s.initial_objective, 1e-9 * s.initial_objective);
}

// A free cube whose initial velocity (|v_i| <= 1 m/s) must lift its centre
// of mass 0.5 m within 50 ms: impossible.
TEST(IpoptSolveTest, UnreachableTerminalConstraintIsReportedInfeasible) {
  Scene scene;
  scene.mesh = BoxHexMesh(2, 2, 2, 0.1, 0.1, 0.1);
  scene.material.youngs_modulus = 1e5;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.gravity = Vec3(0, 0, -9.81);
  std::vector<int> all(scene.mesh.num_vertices());
  for (int i = 0; i < scene.mesh.num_vertices(); ++i) all[i] = i;
  Ipopt::SmartPtr<RolloutNlp> nlp = EmptyNlp(scene, TightNewton(), 5);
  const Simulator& sim = nlp->function().simulator();
  auto v0 = std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, all);
  v0->SetBounds(-1.0, 1.0);
  nlp->AddVariables(std::move(v0));
  nlp->AddRegularization(0, 3, 1.0);
  const TrackedPoint com = CentreOfMass(sim.LumpedMass());
  const double z0 = com.At(sim.RestState().x).z();
  nlp->AddConstraint(std::make_unique<PointCoordinate>(com, kFinalState, Vec3::UnitZ(), "com_z"), z0 + 0.5, 1e20);
  IpoptOptions o;
  o.int_options = {{"max_iter", 200}};
  const IpoptSummary s = SolveWithIpopt(nlp, o);
  EXPECT_TRUE(s.infeasible()) << s.BriefReport() << "\n" << s.log;
  EXPECT_EQ(s.status_name, "Infeasible_Problem_Detected");
  EXPECT_GT(s.constraint_violation, 0.4);
}

TEST(IpoptSolveTest, OptionsPassThroughUnchanged) {
  SteerBeam p(OrdinaryNewton());
  IpoptOptions o;
  o.int_options = {{"max_iter", 2}, {"print_level", 0}};
  o.string_options = {{"mu_strategy", "adaptive"}};
  o.num_options = {{"tol", 1e-10}};
  const IpoptSummary s = SolveWithIpopt(p.nlp, o);
  EXPECT_EQ(s.status, Ipopt::Maximum_Iterations_Exceeded);
  EXPECT_EQ(s.status_name, "Maximum_Iterations_Exceeded");
  EXPECT_EQ(s.iterations, 2);
  EXPECT_TRUE(s.log.empty());  // print_level 0
  IpoptOptions bad;
  bad.int_options = {{"no_such_option", 1}};
  try {
    SolveWithIpopt(p.nlp, bad);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("Ipopt option no_such_option = 1 is invalid"), std::string::npos) << e.what();
  }
  IpoptOptions bad_value;
  bad_value.string_options = {{"hessian_approximation", "sometimes"}};
  EXPECT_THROW(SolveWithIpopt(p.nlp, bad_value), InvalidInputError);
}

TEST(IpoptSolveTest, FailedRolloutsMakeIpoptCutItsStep) {
  // Newton allowed 6 iterations per step: tip forces up to ~0.3 N per node
  // converge, forces >~ 1 N do not (SolverError). The target needs ~0.02 N,
  // but the first quasi-Newton step is huge (steep objective), so Ipopt meets
  // failed rollouts, cuts its step back, and still converges.
  Scene scene = SmallBeamScene();
  scene.gravity.reset();
  SolverOptions options = TightNewton();
  options.rel_tolerance = 1e-9;
  options.max_iterations = 6;
  const std::vector<int> tip = NodesAtXMax(scene.mesh);
  Ipopt::SmartPtr<RolloutNlp> nlp = EmptyNlp(scene, options, 4);
  const Simulator& sim = nlp->function().simulator();
  std::vector<ExternalForceBlock::Channel> channels(1);
  channels[0] = {tip, Vec3::UnitZ(), std::make_unique<PiecewiseLinearSignal>(4, 2)};
  nlp->AddVariables(std::make_unique<ExternalForceBlock>(std::move(channels)));
  const TrackedPoint marker = NodePoint(scene.mesh.num_vertices(), tip[0]);
  nlp->AddObjective(
      std::make_unique<PointDistanceSquared>(marker, kFinalState, marker.At(sim.RestState().x) + Vec3(0, 0, 0.002)),
      1e7);
  IpoptOptions o;
  o.int_options = {{"max_iter", 100}};
  const IpoptSummary s = SolveWithIpopt(nlp, o);
  EXPECT_GT(nlp->statistics().failed_rollouts, 0) << s.log;
  EXPECT_NE(s.log.find("evaluation error"), std::string::npos) << s.log;
  EXPECT_TRUE(s.succeeded()) << s.BriefReport() << "\n" << s.log;
  EXPECT_LE(s.objective, 1e-3 * s.initial_objective) << s.BriefReport();
}

}  // namespace
}  // namespace diffpd::testing
