// The PD methods' adjoint solvers (SolverOptions::adjoint_solver): the
// direct solve of the step Hessian gives the iterative adjoint's gradients
// and both agree with central differences; the automatic choice factorises
// where the iteration needs many iterations and the horizon pays for the
// analysis, makes no factorisation on a tiny free cube, depends on the
// problem alone, and gives the same gradients; the direct solve analyses the Hessian's
// pattern once per simulator; each method reports which solver its steps
// used; tangents agree across the solvers.
#include <gtest/gtest.h>

#include <random>

#include "diffpd/simulator.h"
#include "solver/simulator_impl.h"
#include "test_scenes.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

// The small clamped beam with two muscles along it, moving and deformed.
Scene MuscleBeam() {
  Scene scene = testing::SmallBeamScene();
  Muscle top, bottom;
  for (int e = 0; e < scene.mesh.num_elements(); ++e) {
    double z = 0;
    for (int a = 0; a < 8; ++a) z += scene.mesh.vertices(2, scene.mesh.elements(a, e)) / 8.0;
    (z > 0.02 ? top : bottom).elements.push_back(e);
  }
  top.fibers = {Vec3(1, 0, 0)};
  bottom.fibers = {Vec3(1, 0, 0.2)};
  top.stiffness = 1e5;
  bottom.stiffness = 2e5;
  scene.muscles = {top, bottom};
  return scene;
}

constexpr int kSteps = 4;

std::vector<StepInput> Inputs() {
  std::vector<StepInput> inputs(kSteps);
  for (int i = 0; i < kSteps; ++i) inputs[i].activation = Eigen::Vector2d(0.9 - 0.01 * i, 1.05);
  return inputs;
}

SolverOptions Options(AdjointSolver solver) {
  SolverOptions o = testing::TightOptions(Method::kPdLbfgs);
  o.adjoint_solver = solver;
  return o;
}

// L = c_x . x_K + c_v . v_K with fixed random c.
struct Loss {
  VectorXd cx, cv;
  explicit Loss(int n) {
    std::mt19937_64 rng(11);
    cx = testing::RandomVector(n, &rng, 1.0);
    cv = testing::RandomVector(n, &rng, 1.0);
  }
  double Value(const Rollout& r) const { return cx.dot(r.states.back().x) + cv.dot(r.states.back().v); }
  LossGradient Gradient() const {
    LossGradient g(kSteps);
    g.dx[kSteps] = cx;
    g.dv[kSteps] = cv;
    return g;
  }
};

// Every differentiable input of the gradient in one vector.
VectorXd Stack(const RolloutGradient& g) {
  VectorXd out(2 * g.x0.size() + 3 + 2 * kSteps);
  out.head(2 * g.x0.size() + 3) << g.x0, g.v0, g.youngs_modulus, g.poissons_ratio, g.density;
  for (int i = 0; i < kSteps; ++i) out.segment(2 * g.x0.size() + 3 + 2 * i, 2) = g.activation[i];
  return out;
}

double RelativeDifference(const VectorXd& a, const VectorXd& b) { return (a - b).norm() / b.norm(); }

TEST(AdjointSolverTest, DirectAdjointGivesTheIterativeGradientsAndBothMatchCentralDifferences) {
  const Scene scene = MuscleBeam();
  Simulator iterative_sim(scene, Options(AdjointSolver::kIterative));
  const State start = testing::MovingStart(iterative_sim);
  const Loss loss(iterative_sim.num_dofs());
  const Rollout rollout = iterative_sim.Simulate(start, Inputs());
  const RolloutGradient iterative = iterative_sim.Backward(rollout, loss.Gradient());
  Simulator direct_sim(scene, Options(AdjointSolver::kDirect));
  const RolloutGradient direct = direct_sim.Backward(direct_sim.Simulate(start, Inputs()), loss.Gradient());
  EXPECT_EQ(iterative.report.iterative_steps, kSteps);
  EXPECT_EQ(iterative.report.direct_steps, 0);
  EXPECT_GT(iterative.report.linear_iterations, 0);
  EXPECT_EQ(direct.report.direct_steps, kSteps);
  EXPECT_EQ(direct.report.iterative_steps, 0);
  EXPECT_EQ(direct.report.linear_iterations, 0);
  EXPECT_LT(RelativeDifference(Stack(direct), Stack(iterative)), 1e-9);
  // Central differences of L along the initial positions, Young's modulus
  // and the first step's activations.
  std::mt19937_64 rng(3);
  const VectorXd dx0 = testing::RandomVector(iterative_sim.num_dofs(), &rng, 1.0);
  testing::DifferenceOptions fd;
  fd.noise = 1e-11;  // the forward's tolerance
  fd.rtol = 1e-5;
  const auto check = [&](const char* input, double h, const std::function<double(double)>& loss_at, double analytic_i,
                         double analytic_d) {
    const double plus = loss_at(h), minus = loss_at(-h);
    EXPECT_TRUE(testing::Passes(testing::CompareCentralDifference(plus, minus, h, analytic_i, fd))) << input;
    EXPECT_TRUE(testing::Passes(testing::CompareCentralDifference(plus, minus, h, analytic_d, fd))) << input;
  };
  const auto rollout_loss = [&](const State& s0, const Scene& sc, const std::vector<StepInput>& inputs) {
    Simulator sim(sc, Options(AdjointSolver::kDirect));
    return loss.Value(sim.Simulate(s0, inputs));
  };
  // Positions: the element size is the distance over which L changes.
  check(
      "x0", testing::CentralDifferenceStep(fd.noise, 0.04, dx0.cwiseAbs().maxCoeff()),
      [&](double t) {
        State s = start;
        s.x += t * dx0;
        for (const int d : scene.dirichlet.dofs) s.x(d) = start.x(d);
        return rollout_loss(s, scene, Inputs());
      },
      iterative.x0.dot(dx0), direct.x0.dot(dx0));
  const double e = scene.material.youngs_modulus;
  check(
      "youngs_modulus", testing::CentralDifferenceStep(fd.noise, e),
      [&](double t) {
        Scene sc = scene;
        sc.material.youngs_modulus = e + t;
        return rollout_loss(start, sc, Inputs());
      },
      iterative.youngs_modulus, direct.youngs_modulus);
  check(
      "activation", testing::CentralDifferenceStep(fd.noise, 1.0),
      [&](double t) {
        std::vector<StepInput> inputs = Inputs();
        inputs[0].activation(0) += t;
        return rollout_loss(start, scene, inputs);
      },
      iterative.activation[0](0), direct.activation[0](0));
}

// The loss L = c_x . x_K + c_v . v_K over `steps` steps of the muscle beam
// (activations as Inputs()).
RolloutGradient LongGradient(Simulator* sim, int steps) {
  std::vector<StepInput> inputs(steps);
  for (int i = 0; i < steps; ++i) inputs[i].activation = Eigen::Vector2d(0.9 - 0.005 * i, 1.05);
  const Rollout rollout = sim->Simulate(testing::MovingStart(*sim), inputs);
  LossGradient loss(steps);
  const Loss weights(sim->num_dofs());
  loss.dx[steps] = weights.cx;
  loss.dv[steps] = weights.cv;
  return sim->Backward(rollout, loss);
}

TEST(AdjointSolverTest, AutomaticChoiceFactorisesWhereTheIterationNeedsManyIterationsAndGivesTheSameGradients) {
  // The tests' tight adjoint tolerance (1e-13) on the small muscle beam (135
  // DoFs, a thin factor): dozens of iterations per step, each step's
  // factorisation estimated cheaper.
  constexpr int kLongSteps = 30;
  const Scene scene = MuscleBeam();
  Simulator direct_sim(scene, Options(AdjointSolver::kDirect));
  const RolloutGradient direct = LongGradient(&direct_sim, kLongSteps);
  Simulator iterative_sim(scene, Options(AdjointSolver::kIterative));
  const RolloutGradient iterative = LongGradient(&iterative_sim, kLongSteps);
  EXPECT_GE(iterative.report.linear_iterations, 20 * kLongSteps);
  Simulator auto_sim(scene, Options(AdjointSolver::kAuto));
  const RolloutGradient automatic = LongGradient(&auto_sim, kLongSteps);
  // The first step (in reverse) counts the iteration; afterwards the
  // factorisation serves every step but the iteration's rechecks (at most
  // one per 8 direct steps).
  constexpr int kMostRechecks = kLongSteps / internal::AdjointCostModel::kMinRecheck;
  EXPECT_GE(automatic.report.iterative_steps, 1);
  EXPECT_LE(automatic.report.iterative_steps, 1 + kMostRechecks);
  EXPECT_EQ(automatic.report.iterative_steps + automatic.report.direct_steps, kLongSteps);
  EXPECT_EQ(automatic.report.fallbacks, 0);
  const auto stack = [](const RolloutGradient& g) {
    VectorXd out(2 * g.x0.size() + 3);
    out << g.x0, g.v0, g.youngs_modulus, g.poissons_ratio, g.density;
    return out;
  };
  EXPECT_LT(RelativeDifference(stack(automatic), stack(direct)), 1e-9);
  EXPECT_LT(RelativeDifference(stack(automatic), stack(iterative)), 1e-9);
  // Over 4 steps the same beam iterates throughout: the one-off analysis of
  // H, spread over the 3 steps left after the first, would cost more than
  // the factorisation saves. Whatever the horizon, the same gradient.
  Simulator short_sim(scene, Options(AdjointSolver::kAuto));
  const Loss loss(short_sim.num_dofs());
  const RolloutGradient short_auto =
      short_sim.Backward(short_sim.Simulate(testing::MovingStart(short_sim), Inputs()), loss.Gradient());
  EXPECT_EQ(short_auto.report.direct_steps, 0);
  EXPECT_EQ(short_auto.report.iterative_steps, kSteps);
}

TEST(AdjointSolverTest, AutomaticChoiceMakesNoTrialFactorisationOnATinyFreeCubeAndDependsOnTheProblemAlone) {
  // A free-falling 4 x 4 x 4 hexahedral cube (375 DoFs) at the library's
  // default tolerances: 10-20 iterations per step, each step's iteration
  // estimated cheaper than a factorisation of H (a cube's factor fills in).
  Scene scene;
  scene.mesh = testing::BoxHexMesh(4, 4, 4, 0.1, 0.1, 0.1);
  scene.material.youngs_modulus = 2e5;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.num_threads = 1;
  ASSERT_EQ(options.adjoint_solver, AdjointSolver::kAuto);
  constexpr int kLongSteps = 30;
  const auto gradient = [&] {
    Simulator sim(scene, options);
    const Rollout rollout = sim.Simulate(testing::MovingStart(sim), std::vector<StepInput>(kLongSteps));
    LossGradient loss(kLongSteps);
    const Loss weights(sim.num_dofs());
    loss.dx[kLongSteps] = weights.cx;
    loss.dv[kLongSteps] = weights.cv;
    return sim.Backward(rollout, loss);
  };
  const RolloutGradient automatic = gradient();
  EXPECT_EQ(automatic.report.direct_steps, 0);
  EXPECT_EQ(automatic.report.fallbacks, 0);
  EXPECT_EQ(automatic.report.iterative_steps, kLongSteps);
  EXPECT_GE(automatic.report.linear_iterations, 5 * kLongSteps);
  // A second simulator makes the same choices and the same gradient, bit for
  // bit (no clock enters the choice).
  const RolloutGradient again = gradient();
  EXPECT_EQ(again.report.linear_iterations, automatic.report.linear_iterations);
  EXPECT_EQ(again.x0, automatic.x0);
  EXPECT_EQ(again.v0, automatic.v0);
}

TEST(AdjointSolverTest, TangentsAgreeAcrossTheAdjointSolvers) {
  const Scene scene = MuscleBeam();
  std::vector<InputDirection> directions = {InputDirection::YoungsModulus(), InputDirection::Density()};
  InputDirection activation;
  activation.activation.assign(kSteps, Eigen::Vector2d(1.0, -0.5));
  directions.push_back(activation);
  std::vector<TangentRollout> tangents;
  for (const AdjointSolver solver : {AdjointSolver::kDirect, AdjointSolver::kIterative, AdjointSolver::kAuto}) {
    Simulator sim(scene, Options(solver));
    const Rollout r = sim.Simulate(testing::MovingStart(sim), Inputs());
    tangents.push_back(sim.Tangents(r, directions));
    const BackwardReport& report = tangents.back().report;
    EXPECT_EQ(report.iterative_steps + report.direct_steps, kSteps) << ToString(solver);
    if (solver == AdjointSolver::kDirect) {
      EXPECT_EQ(report.direct_steps, kSteps);
    }
    if (solver == AdjointSolver::kIterative) {
      EXPECT_EQ(report.iterative_steps, kSteps);
    }
  }
  for (size_t t = 1; t < tangents.size(); ++t)
    for (int k = 1; k <= kSteps; ++k)
      EXPECT_LT((tangents[t].dx[k] - tangents[0].dx[k]).norm(), 1e-9 * tangents[0].dx[k].norm()) << t << " " << k;
}

TEST(AdjointSolverTest, DirectSolvesAnalyseTheHessianPatternOncePerSimulator) {
  const Scene scene = MuscleBeam();
  const SolverOptions options = Options(AdjointSolver::kDirect);
  internal::SimulatorImpl sim(scene, options);
  sim.activation = Eigen::Vector2d(0.9, 1.05);
  Simulator stepper(scene, options);
  const Rollout r = stepper.Simulate(testing::MovingStart(stepper), Inputs());
  const VectorXd b = VectorXd::LinSpaced(sim.num_dofs(), -1, 1);
  for (int k = 1; k <= kSteps; ++k) {
    internal::StepLinearization lin(sim, r.states[k].x);
    BackwardReport report;
    const VectorXd z = lin.Solve(b, &report);
    VectorXd free_b = b;
    sim.ZeroFixed(&free_b);
    EXPECT_LT((lin.Apply(z) - free_b).norm(), 1e-10 * free_b.norm()) << k;
    EXPECT_EQ(report.direct_steps, 1);
  }
  EXPECT_EQ(sim.hessian_factorization().num_factorizations(), kSteps);
  EXPECT_EQ(sim.hessian_factorization().num_analyses(), 1);
}

// The smallest eigenvalue of H on the free DoFs, from H's columns.
double SmallestFreeEigenvalue(internal::SimulatorImpl& sim, internal::StepLinearization* lin) {
  std::vector<int> free;
  for (int d = 0; d < sim.num_dofs(); ++d)
    if (!sim.fixed[d]) free.push_back(d);
  MatrixXd h(free.size(), free.size());
  for (size_t j = 0; j < free.size(); ++j) {
    VectorXd e = VectorXd::Zero(sim.num_dofs());
    e(free[j]) = 1;
    const VectorXd column = lin->Apply(e);
    for (size_t i = 0; i < free.size(); ++i) h(i, j) = column(free[i]);
  }
  return Eigen::SelfAdjointEigenSolver<MatrixXd>(0.5 * (h + h.transpose())).eigenvalues().minCoeff();
}

TEST(AdjointSolverTest, AnIndefiniteStepHessianIsCountedAndAPositiveDefiniteOneIsNot) {
  SolverOptions o = testing::TightOptions(Method::kPdLbfgs);
  o.adjoint_solver = AdjointSolver::kDirect;
  o.time_step = 0.1;  // a small inertial term M/h^2
  const Scene scene = testing::SmallBeamScene();
  internal::SimulatorImpl sim(scene, o);
  const VectorXd rest = Simulator(scene, o).RestState().x;
  VectorXd squashed = rest;  // the beam compressed to a third of its length: no minimum of the step's energy
  for (int i = 0; i < squashed.size() / 3; ++i) squashed(3 * i) *= 1.0 / 3.0;
  const VectorXd b = VectorXd::LinSpaced(sim.num_dofs(), -1, 1);
  for (const bool compressed : {false, true}) {
    internal::StepLinearization lin(sim, compressed ? squashed : rest);
    const double smallest = SmallestFreeEigenvalue(sim, &lin);
    ASSERT_EQ(smallest < 0, compressed) << "smallest eigenvalue of H " << smallest;
    BackwardReport report;
    const VectorXd z = lin.Solve(b, &report);
    VectorXd free_b = b;
    sim.ZeroFixed(&free_b);
    EXPECT_LT((lin.Apply(z) - free_b).norm(), 1e-8 * free_b.norm()) << compressed;
    EXPECT_EQ(report.indefinite_steps, compressed ? 1 : 0);
    lin.Solve(b, &report);  // a second solve at the same step counts no second step
    EXPECT_EQ(report.indefinite_steps, compressed ? 1 : 0);
  }
}

TEST(AdjointSolverTest, EveryMethodReportsWhichSolverItsBackwardStepsUsed) {
  const Scene scene = MuscleBeam();
  for (const Method m : {Method::kNewtonCholesky, Method::kNewtonLdlt, Method::kNewtonPcg, Method::kPd}) {
    SolverOptions o = testing::TightOptions(m);
    o.adjoint_solver = AdjointSolver::kIterative;
    Simulator sim(scene, o);
    const Loss loss(sim.num_dofs());
    const RolloutGradient g = sim.Backward(sim.Simulate(testing::MovingStart(sim), Inputs()), loss.Gradient());
    const bool iterative = m == Method::kNewtonPcg || m == Method::kPd;
    EXPECT_EQ(g.report.iterative_steps, iterative ? kSteps : 0) << ToString(m);
    EXPECT_EQ(g.report.direct_steps, iterative ? 0 : kSteps) << ToString(m);
  }
}

}  // namespace
}  // namespace diffpd
