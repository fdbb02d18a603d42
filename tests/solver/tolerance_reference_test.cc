// SolverOptions::tolerance_reference: the step test relative to the start
// residual (default) or to the inertial term |(M / h^2)(x_i + h v_i) + f|.
#include <gtest/gtest.h>

#include "diffpd/simulator.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

SolverOptions Options(ToleranceReference reference) {
  SolverOptions o;
  o.method = Method::kPdLbfgs;
  o.time_step = 0.01;
  o.rel_tolerance = 1e-4;
  o.tolerance_reference = reference;
  return o;
}

// The clamped beam at rest, its free nodes moving up in proportion to their y.
State MovingState(const Simulator& sim) {
  State s = sim.RestState();
  for (Eigen::Index i = 0; i < s.x.size() / 3; ++i) s.v(3 * i + 2) = 5.0 * s.x(3 * i + 1);
  for (int d : sim.scene().dirichlet.dofs) s.v(d) = 0;
  return s;
}

// The small clamped beam moved 1 m along x (the inertial term grows with the
// distance from the origin).
Scene ShiftedBeamScene() {
  Scene scene = testing::SmallBeamScene();
  for (int i = 0; i < scene.mesh.num_vertices(); ++i) scene.mesh.vertices(0, i) += 1.0;
  for (Eigen::Index k = 0; k < scene.dirichlet.values.size(); ++k)
    if (scene.dirichlet.dofs[k] % 3 == 0) scene.dirichlet.values(k) += 1.0;
  return scene;
}

TEST(ToleranceReferenceTest, InertiaReferenceIsTheInertialTermOverTheFreeDofs) {
  const Scene scene = ShiftedBeamScene();
  Simulator sim(scene, Options(ToleranceReference::kInertia));
  const State s = MovingState(sim);
  StepReport report;
  sim.Step(s, StepInput(), &report);
  const double h = 0.01;
  const VectorXd m = sim.LumpedMass();
  std::vector<char> fixed(s.x.size(), 0);
  for (int d : scene.dirichlet.dofs) fixed[d] = 1;
  double squares = 0;
  for (Eigen::Index d = 0; d < s.x.size(); ++d) {
    if (fixed[d]) continue;
    const double gravity = d % 3 == 2 ? m(d) * (*scene.gravity)(2) : 0.0;
    const double term = m(d) / (h * h) * (s.x(d) + h * s.v(d)) + gravity;
    squares += term * term;
  }
  EXPECT_NEAR(report.initial_residual, std::sqrt(squares), 1e-12 * std::sqrt(squares));
  EXPECT_LE(report.final_residual, 1e-9 + 1e-4 * report.initial_residual);
}

TEST(ToleranceReferenceTest, TheInertiaReferenceOfABodyAwayFromTheOriginIsLooserThanTheStartResidual) {
  const Scene scene = ShiftedBeamScene();
  Simulator start(scene, Options(ToleranceReference::kStartResidual));
  Simulator inertia(scene, Options(ToleranceReference::kInertia));
  StepReport a, b;
  start.Step(MovingState(start), StepInput(), &a);
  inertia.Step(MovingState(inertia), StepInput(), &b);
  EXPECT_GT(b.initial_residual, 10 * a.initial_residual);
  EXPECT_LT(b.iterations, a.iterations);
}

}  // namespace
}  // namespace diffpd
