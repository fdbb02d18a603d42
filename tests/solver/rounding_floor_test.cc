// A step whose tolerance lies below what double precision can resolve ends
// at g's rounding floor (SolverOptions::accept_rounding_floor) instead of
// failing; a stall above the floor is still an error.
#include <gtest/gtest.h>

#include <string>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "solver/line_search.h"
#include "solver/simulator_impl.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

using internal::SimulatorImpl;
using internal::StepObjective;

// A very stiff clamped beam (E = 1e10 Pa) settling under gravity at
// h = 1 ms: after a few steps |grad g| of a step starting at rest is at the
// rounding floor, far above the default abs_tolerance of 1e-9 N.
Scene StiffBeam() {
  Scene scene = testing::SmallBeamScene();
  scene.material.youngs_modulus = 1e10;
  scene.material.poissons_ratio = 0.3;
  return scene;
}

SolverOptions StiffOptions(Method method, bool accept) {
  SolverOptions o;
  o.method = method;
  o.time_step = 1e-3;
  o.num_threads = 1;
  o.accept_rounding_floor = accept;
  return o;
}

constexpr int kSteps = 40;

TEST(RoundingFloorTest, StiffBeamAtRestEndsItsStepsAtTheFloorInsteadOfFailing) {
  for (Method method : {Method::kPdLbfgs, Method::kNewtonCholesky}) {
    SCOPED_TRACE(ToString(method));
    Simulator sim(StiffBeam(), StiffOptions(method, true));
    const Rollout r = sim.Simulate(sim.RestState(), std::vector<StepInput>(kSteps));
    int floor_stops = 0;
    for (const StepReport& report : r.reports) {
      floor_stops += report.rounding_floor_stop;
      if (report.rounding_floor_stop) {
        // Above the test, yet within the acceptance band of the floor.
        EXPECT_GT(report.final_residual, 1e-9);
      }
    }
    EXPECT_GT(floor_stops, 0);
    for (const State& s : r.states) EXPECT_TRUE(s.x.allFinite() && s.v.allFinite());
    // At rest under gravity: the last velocity is the rounding's, not motion.
    EXPECT_LT(r.states.back().v.cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(RoundingFloorTest, WithoutAcceptanceTheSameStallIsALineSearchError) {
  for (Method method : {Method::kPdLbfgs, Method::kNewtonCholesky}) {
    SCOPED_TRACE(ToString(method));
    Simulator sim(StiffBeam(), StiffOptions(method, false));
    try {
      sim.Simulate(sim.RestState(), std::vector<StepInput>(kSteps));
      ADD_FAILURE() << "expected a line search failure";
    } catch (const SolverError& e) {
      EXPECT_EQ(e.status(), SolverStatus::kLineSearchFailed);
      EXPECT_NE(std::string(e.what()).find("estimated rounding floor"), std::string::npos) << e.what();
    }
  }
}

TEST(RoundingFloorTest, AStallFarAboveTheFloorIsStillAnError) {
  SimulatorImpl sim(testing::SmallBeamScene(), StiffOptions(Method::kNewtonCholesky, true));
  State s;
  s.x = Eigen::Map<const VectorXd>(sim.scene.mesh.vertices.data(), sim.num_dofs());
  s.v = VectorXd::Constant(sim.num_dofs(), 0.3);
  sim.ZeroFixed(&s.v);
  StepObjective objective(sim, s.x + sim.h() * s.v, sim.ExplicitForce(StepInput()));
  VectorXd x = s.x, grad;
  double value = objective.Evaluate(x, &grad);
  ASSERT_GT(grad.norm(), 1e6 * objective.RoundingFloor());
  // A descent direction too short to move any coordinate: every trial is x.
  const VectorXd d = -1e-300 * grad;
  try {
    internal::BacktrackingLineSearch(objective, d, &x, &value, &grad);
    ADD_FAILURE() << "expected a line search failure";
  } catch (const SolverError& e) {
    EXPECT_EQ(e.status(), SolverStatus::kLineSearchFailed);
  }
}

TEST(RoundingFloorTest, TheSameStallAtRestIsTheFloor) {
  SimulatorImpl sim(StiffBeam(), StiffOptions(Method::kNewtonCholesky, true));
  // Converge a step from rest tightly enough that |grad g| is at the floor.
  Simulator outer(StiffBeam(), StiffOptions(Method::kNewtonCholesky, true));
  State s = outer.RestState();
  for (int k = 0; k < kSteps; ++k) s = outer.Step(s, StepInput());
  StepObjective objective(sim, s.x + sim.h() * s.v, sim.ExplicitForce(StepInput()));
  VectorXd x = s.x, grad;
  double value = objective.Evaluate(x, &grad);
  ASSERT_LE(grad.norm(), StepObjective::kRoundingFloorStall * objective.RoundingFloor());
  const VectorXd d = -1e-300 * grad;
  const internal::LineSearchResult result = internal::BacktrackingLineSearch(objective, d, &x, &value, &grad);
  EXPECT_TRUE(result.at_rounding_floor);
  EXPECT_EQ(x, s.x);
}

// The floor's elastic part grows with the stiffness: 1e4 times the modulus,
// about 1e4 times the floor of a step at rest (the inertia and gravity parts
// are unchanged and small).
TEST(RoundingFloorTest, FloorScalesWithTheElasticModulus) {
  Scene soft = StiffBeam();
  soft.material.youngs_modulus = 1e6;
  SimulatorImpl stiff_sim(StiffBeam(), StiffOptions(Method::kPdLbfgs, true));
  SimulatorImpl soft_sim(soft, StiffOptions(Method::kPdLbfgs, true));
  const VectorXd x = Eigen::Map<const VectorXd>(stiff_sim.scene.mesh.vertices.data(), stiff_sim.num_dofs());
  StepObjective stiff(stiff_sim, x, stiff_sim.ExplicitForce(StepInput()));
  StepObjective soft_objective(soft_sim, x, soft_sim.ExplicitForce(StepInput()));
  const double ratio = stiff.RoundingFloor() / soft_objective.RoundingFloor();
  EXPECT_GT(ratio, 1e3);
  EXPECT_LT(ratio, 1.0001e4);
}

}  // namespace
}  // namespace diffpd
