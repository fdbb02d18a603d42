// Terms for the rollout-set tests (LocalRolloutSet, DistributedRolloutSet):
// the small clamped beam started with a push that differs per term, Young's
// modulus (in units of 1e5 Pa) and Poisson's ratio as the parameters, and
// 2 + t mod 3 rows of the free tip's coordinates at steps 2 and 4.
#pragma once

#include <memory>

#include "diffpd/solvers/core/material_block.h"
#include "diffpd/solvers/core/rollout_set.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "test_scenes.h"

namespace diffpd::testing {

inline constexpr int kRolloutSetTermSteps = 4;

inline solvers::RolloutTerm BeamTerm(int t, int max_iterations = 20000) {
  using namespace solvers;
  Scene scene = SmallBeamScene();
  SolverOptions options = TightOptions(Method::kPdLbfgs);
  options.max_iterations = max_iterations;
  auto f = std::make_unique<RolloutFunction>(scene, options, kRolloutSetTermSteps);
  State start = MovingStart(f->simulator());
  start.v *= 1.0 + 0.5 * t;
  for (int d : scene.dirichlet.dofs) start.v(d) = 0;
  f->SetInitialState(start);
  f->AddBlock(std::make_unique<MaterialBlock>(
      std::vector<MaterialBlock::Entry>{MaterialBlock::Entry(MaterialField::kYoungsModulus, kBaseMaterial, 1e5),
                                        MaterialField::kPoissonsRatio},
      scene));
  const int n = scene.mesh.num_vertices();
  const TrackedPoint tip = NodePoint(n, n - 1);
  RolloutTerm term;
  const Vec3 axes[3] = {Vec3::UnitZ(), Vec3::UnitY(), Vec3::UnitX()};
  for (int r = 0; r < 2 + t % 3; ++r) {
    const int step = r % 2 == 0 ? 2 : 4;
    term.rows.push_back(
        f->functional_row(f->AddFunctional(std::make_unique<PointCoordinate>(tip, step, axes[r / 2 % 3]))));
  }
  term.function = std::move(f);
  return term;
}

}  // namespace diffpd::testing
