// Fits Young's modulus and Poisson's ratio of a soft body to captured marker
// motion: the README's example program (compiled and run by
// readme_example_test). Usage: readme_example MESH.obj MOTION.csv
#include <cstdio>

#include <ceres/ceres.h>

#include "diffpd/captured_motion.h"
#include "diffpd/solvers/ceres/coordinate_manifold.h"
#include "diffpd/solvers/ceres/rollout_cost_function.h"
#include "diffpd/solvers/ceres/rollout_evaluation_callback.h"
#include "diffpd/solvers/core/marker_residuals.h"
#include "diffpd/solvers/core/material_block.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/voxelizer.h"

int main(int argc, char** argv) {
  using namespace diffpd;
  using namespace diffpd::solvers;
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s MESH.obj MOTION.csv\n", argv[0]);
    return 2;
  }
  // The scene: the surface voxelised into 1 cm hexahedra, clamped where x is
  // smallest, under gravity; the material is the starting guess (rho known).
  Scene scene;
  scene.mesh = VoxelizeSurface(ReadObj(argv[1]), 0.01);
  const double x_min = scene.mesh.vertices.row(0).minCoeff();
  std::vector<int> clamped;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) < x_min + 1e-6) clamped.push_back(i);
  FixNodes(&scene, clamped);
  scene.gravity = Vec3(0, 0, -9.81);
  scene.material = MaterialParameters{1e5, 0.45, 1e3};
  SolverOptions options;
  options.method = Method::kNewtonCholesky;  // h = 0.01 s by default
  options.rel_tolerance = 1e-9;
  const CapturedMotion motion = ReadCapturedMotion(argv[2]);  // markers and samples
  const int steps = MarkerObservations::RequiredSteps(motion, options.time_step);

  // The differentiable rollout: parameters {E, nu}, rows the marker residuals.
  RolloutFunction rollout(scene, options, steps);
  rollout.AddBlock(std::make_unique<MaterialBlock>(
      std::vector<MaterialBlock::Entry>{MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio}, scene));
  const int markers =
      rollout.AddFunctional(std::make_unique<MarkerResiduals>(motion, scene.mesh, options.time_step, steps));

  double material[2] = {scene.material.youngs_modulus, scene.material.poissons_ratio};
  RolloutEvaluationCallback callback(&rollout, {material});  // one rollout per point
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &callback;
  ceres::Problem problem(problem_options);
  AddMarkerResidualBlocks(&problem, &rollout, markers, {material});  // one block per frame, exact Jacobians
  problem.SetManifold(material, new CoordinateManifold({CoordinateMap::Log(), CoordinateMap::Linear()}));
  problem.SetParameterLowerBound(material, 1, 0.01);  // Poisson's ratio in [0.01, 0.49]
  problem.SetParameterUpperBound(material, 1, 0.49);

  ceres::Solver::Options solve_options;
  solve_options.minimizer_progress_to_stdout = true;
  ceres::Solver::Summary summary;
  ceres::Solve(solve_options, &problem, &summary);
  std::printf("%s\nE = %.9g Pa, nu = %.9g (%ld rollouts, %.2f s forward, %.2f s derivatives)\n",
              summary.BriefReport().c_str(), material[0], material[1], rollout.statistics().rollouts,
              rollout.statistics().forward_seconds, rollout.statistics().backward_seconds);
  return summary.IsSolutionUsable() ? 0 : 1;
}
