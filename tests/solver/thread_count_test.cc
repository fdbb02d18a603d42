// The number of threads (SolverOptions::num_threads) changes only the order
// of sums: the element loops and PD's triangular solves (its factor's copy
// split over elimination subtrees) on 2 threads give the same rollout and
// gradient as on 1, to the solves' tolerance.
//
// Property: a PD-LBFGS rollout of a beam whose PD factor is large enough to
// be solved in parallel (the cantilever's 33 x 9 x 9 node grid), and its
// backward pass, agree on 1 and 2 threads.
#include <gtest/gtest.h>

#include "diffpd/simulator.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

Scene CantileverGridScene() {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(32, 8, 8, 0.32, 0.08, 0.08);
  scene.material.youngs_modulus = 1e6;
  scene.material.poissons_ratio = 0.45;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  FixNodes(&scene, testing::NodesAtXMin(scene.mesh));
  return scene;
}

struct Result {
  Rollout rollout;
  RolloutGradient gradient;
};

Result RunOnThreads(int threads) {
  SolverOptions o;
  o.method = Method::kPdLbfgs;
  o.time_step = 0.01;
  o.rel_tolerance = 1e-9;
  o.abs_tolerance = 1e-12;
  o.backward_rel_tolerance = 1e-10;
  o.num_threads = threads;
  Simulator sim(CantileverGridScene(), o);
  Result r;
  r.rollout = sim.Simulate(sim.RestState(), std::vector<StepInput>(3));
  LossGradient dl(3);
  dl.dx[3] = VectorXd::LinSpaced(sim.num_dofs(), -1.0, 1.0);
  r.gradient = sim.Backward(r.rollout, dl);
  return r;
}

TEST(ThreadCountTest, TwoThreadsGiveTheOneThreadRolloutAndGradient) {
  const Result one = RunOnThreads(1), two = RunOnThreads(2);
  const State& a = one.rollout.states.back();
  const State& b = two.rollout.states.back();
  EXPECT_LT((b.x - a.x).norm(), 1e-9 * a.x.norm());
  EXPECT_LT((b.v - a.v).norm(), 1e-6 * a.v.norm());
  EXPECT_LT((two.gradient.x0 - one.gradient.x0).norm(), 1e-7 * one.gradient.x0.norm());
  EXPECT_LT((two.gradient.v0 - one.gradient.v0).norm(), 1e-7 * one.gradient.v0.norm());
}

}  // namespace
}  // namespace diffpd
