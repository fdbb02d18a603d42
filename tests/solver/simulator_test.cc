// Simulator::Step never returns garbage: a step whose residual or state
// overflows double precision, or whose state leaves every physical scale,
// is a SolverError with a specific status and message, for every method.
// (Gradients are checked in simulator_gradient_test, bad inputs in
// solver_options_test.)
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

// One step of the beam (test_scenes.h) that must fail: what to change, and
// the status and exact message expected.
struct FailingStep {
  const char* name;
  Method method;
  std::function<void(Scene*, SolverOptions*, StepInput*)> spoil;
  SolverStatus status;
  // The exact message; each '*' in it stands for a number that depends on
  // rounding in the elastic kernels (the rest must match exactly).
  std::string message;
  int steps = 1;  // the error must come within this many steps
  // The first state (default: rest).
  std::function<State(const Simulator&)> start = nullptr;
};

std::string Describe(SolverStatus s) { return ToString(s); }

bool Matches(const std::string& message, const std::string& pattern) {
  // The pattern's pieces between the '*'s, in order, the first at the start
  // and the last at the end.
  size_t at = 0, from = 0;
  for (size_t star = pattern.find('*'); star != std::string::npos; star = pattern.find('*', from)) {
    const std::string piece = pattern.substr(from, star - from);
    const size_t found =
        from == 0 ? (message.compare(0, piece.size(), piece) == 0 ? 0 : std::string::npos) : message.find(piece, at);
    if (found == std::string::npos) return false;
    at = found + piece.size();
    from = star + 1;
  }
  const std::string last = pattern.substr(from);
  if (from == 0) return message == pattern;
  return message.size() >= at + last.size() && message.compare(message.size() - last.size(), last.size(), last) == 0;
}

void ExpectFailures(const std::vector<FailingStep>& cases) {
  for (const FailingStep& c : cases) {
    Scene scene = testing::SmallBeamScene();
    SolverOptions options;
    options.method = c.method;
    options.num_threads = 1;
    StepInput input;
    c.spoil(&scene, &options, &input);
    Simulator sim(scene, options);
    try {
      State state = c.start ? c.start(sim) : sim.RestState();
      for (int k = 0; k < c.steps; ++k) state = sim.Step(state, input);
      ADD_FAILURE() << c.name << ": no error; |x| = " << state.x.norm();
    } catch (const SolverError& e) {
      EXPECT_EQ(Describe(e.status()), Describe(c.status)) << c.name << ": " << e.what();
      EXPECT_TRUE(Matches(e.what(), c.message)) << c.name << ":\n  " << e.what() << "\nexpected\n  " << c.message;
    }
  }
}

const Method kImplicit[] = {Method::kPd, Method::kPdLbfgs, Method::kNewtonCholesky, Method::kNewtonPcg};

// An external force of 1e300 N per DoF overflows |grad g| (the sum of the
// squares); inf <= inf once counted as converged after 0 iterations.
TEST(SimulatorTest, AnOverflowingResidualIsAnErrorForEveryImplicitMethod) {
  std::vector<FailingStep> cases;
  for (const Method m : kImplicit)
    cases.push_back({"force 1e300", m,
                     [](Scene* s, SolverOptions*, StepInput* in) {
                       in->external_force = VectorXd::Constant(s->mesh.num_dofs(), 1e300);
                     },
                     SolverStatus::kNonFinite,
                     std::string(ToString(m)) +
                         ": the residual |grad g| = inf at iteration 0 (initial inf) is not finite: the step's forces "
                         "or stiffness overflow double precision"});
  ExpectFailures(cases);
}

// A force of 1e153 N per DoF keeps |grad g| finite, but g is not finite at
// any point along the search direction (once reported as a stall, "no
// decrease of g").
TEST(SimulatorTest, LineSearchesReportOverflowAsNonFinite) {
  std::vector<FailingStep> cases;
  for (const Method m : {Method::kPdLbfgs, Method::kNewtonCholesky, Method::kNewtonPcg}) {
    cases.push_back({"force 1e153", m,
                     [](Scene* s, SolverOptions*, StepInput* in) {
                       in->external_force = VectorXd::Constant(s->mesh.num_dofs(), 1e153);
                     },
                     SolverStatus::kNonFinite,
                     std::string(ToString(m)) +
                         ": g is not finite at any line search point x + d / 2^k, k = 0..40 "
                         "(|grad g| = *): the step's forces or stiffness overflow double precision"});
  }
  ExpectFailures(cases);
}

TEST(SimulatorTest, AStiffnessThatOverflowsIsAnErrorForEveryImplicitMethod) {
  std::vector<FailingStep> cases;
  for (const Method m : kImplicit)
    cases.push_back({"E 1e200", m, [](Scene* s, SolverOptions*, StepInput*) { s->material.youngs_modulus = 1e200; },
                     SolverStatus::kNonFinite,
                     std::string(ToString(m)) +
                         ": the residual |grad g| = inf at iteration 0 (initial inf) is not finite: the step's forces "
                         "or stiffness overflow double precision"});
  ExpectFailures(cases);
}

// Semi-implicit Euler at h = 1e3 s tears the clamped beam apart within three
// steps; a force of 1e300 N per DoF within one; a free body expanding at
// 10/s for 1 s is 11 times its size, beyond a bound of 10.
TEST(SimulatorTest, AStepThatTearsTheBodyApartIsReportedAsDiverged) {
  const auto expanding = [](const Simulator& sim) {
    State s = sim.RestState();
    const Vec3 centre(0.08, 0.02, 0.02);  // the beam's
    for (int i = 0; i < s.x.size() / 3; ++i) s.v.segment<3>(3 * i) = 10 * (s.x.segment<3>(3 * i) - centre);
    return s;
  };
  ExpectFailures({
      {"semi-implicit at h = 1e3 s", Method::kSemiImplicit,
       [](Scene*, SolverOptions* o, StepInput*) { o->time_step = 1e3; }, SolverStatus::kDiverged,
       "semi-implicit: the step diverged: the body's extent (its bounding box's diagonal) grew to * m, beyond "
       "max_extent_ratio = 1000 times its rest extent 0.169706 m (h = 1000 s, above semi-implicit Euler's stability "
       "limit at the rest shape, about * s: use a smaller time step or an implicit method)",
       3},
      {"semi-implicit, force 1e300", Method::kSemiImplicit,
       [](Scene* s, SolverOptions*, StepInput* in) {
         in->external_force = VectorXd::Constant(s->mesh.num_dofs(), 1e300);
       },
       SolverStatus::kDiverged,
       "semi-implicit: the step diverged: the body's extent (its bounding box's diagonal) grew to * m, beyond "
       "max_extent_ratio = 1000 times its rest extent 0.169706 m (h = 0.01 s, above semi-implicit Euler's stability "
       "limit at the rest shape, about * s: use a smaller time step or an implicit method)"},
      {"an expanding free body", Method::kSemiImplicit,
       [](Scene* s, SolverOptions* o, StepInput*) {
         s->dirichlet = DirichletBoundary();
         o->time_step = 1.0;
         o->max_extent_ratio = 10;
       },
       SolverStatus::kDiverged,
       "semi-implicit: the step diverged: the body's extent (its bounding box's diagonal) grew to 1.86676 m, beyond "
       "max_extent_ratio = 10 times its rest extent 0.169706 m (h = 1 s, above semi-implicit Euler's stability limit "
       "at "
       "the rest shape, about * s: use a smaller time step or an implicit method)",
       1, expanding},
  });
}

// Rigid motion is never divergence, however far: the free beam falls 2e5 m
// in 20 steps of 10 s.
TEST(SimulatorTest, AFarFallIsNotDivergence) {
  Scene scene = testing::SmallBeamScene();
  scene.dirichlet = DirichletBoundary();
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  options.time_step = 10;
  options.num_threads = 1;
  Simulator sim(scene, options);
  const Rollout r = sim.Simulate(sim.RestState(), std::vector<StepInput>(20));
  EXPECT_LT(r.states.back().x(2), -1e5);
}

// A loss gradient of 1e307 per entry is finite, but the adjoint it starts
// overflows: Backward and Tangents report it instead of returning inf.
TEST(SimulatorTest, DerivativesThatOverflowAreErrors) {
  for (const Method m : {Method::kPd, Method::kNewtonCholesky, Method::kSemiImplicit}) {
    SolverOptions options;
    options.method = m;
    options.time_step = m == Method::kSemiImplicit ? 1e-4 : 0.01;
    options.num_threads = 1;
    Simulator sim(testing::SmallBeamScene(), options);
    const Rollout rollout = sim.Simulate(sim.RestState(), std::vector<StepInput>(3));
    LossGradient loss(3);
    loss.dx[3] = VectorXd::Constant(sim.num_dofs(), 1e307);
    loss.dv[3] = VectorXd::Constant(sim.num_dofs(), 1e307);
    try {
      sim.Backward(rollout, loss);
      ADD_FAILURE() << ToString(m) << ": no error";
    } catch (const SolverError& e) {
      EXPECT_EQ(Describe(e.status()), Describe(SolverStatus::kNonFinite));
      EXPECT_TRUE(
          Matches(e.what(), std::string(ToString(m)) + " backward: the adjoint overflowed double precision (*)"))
          << e.what();
    }
    InputDirection huge;
    huge.x0 = huge.v0 = VectorXd::Constant(sim.num_dofs(), 1e307);
    try {
      sim.Tangents(rollout, {huge});
      ADD_FAILURE() << ToString(m) << ": no error";
    } catch (const SolverError& e) {
      EXPECT_EQ(Describe(e.status()), Describe(SolverStatus::kNonFinite));
      EXPECT_TRUE(
          Matches(e.what(), std::string(ToString(m)) + " tangent: the tangents overflowed double precision (*)"))
          << e.what();
    }
  }
}

}  // namespace
}  // namespace diffpd
