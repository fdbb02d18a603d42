// Fits Young's modulus and Poisson's ratio of a soft body to captured marker
// motion: the README's example program (compiled and run by
// readme_example_test). Usage: readme_example MESH.obj MOTION.csv
#include <cstdio>

#include <ceres/ceres.h>

#include "diffpd/captured_motion.h"
#include "diffpd/solvers/coordinate_manifold.h"
#include "diffpd/solvers/marker_cost_function.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/voxelizer.h"

int main(int argc, char** argv) {
  using namespace diffpd;
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s MESH.obj MOTION.csv\n", argv[0]);
    return 2;
  }
  // The scene: the surface voxelised into 1 cm hexahedra, clamped where x is
  // smallest, under gravity; the material is the starting guess (rho known).
  solvers::CalibrationSetup setup;
  setup.scene.mesh = VoxelizeSurface(ReadObj(argv[1]), 0.01);
  const double x_min = setup.scene.mesh.vertices.row(0).minCoeff();
  std::vector<int> clamped;
  for (int i = 0; i < setup.scene.mesh.num_vertices(); ++i)
    if (setup.scene.mesh.vertices(0, i) < x_min + 1e-6) clamped.push_back(i);
  FixNodes(&setup.scene, clamped);
  setup.scene.gravity = Vec3(0, 0, -9.81);
  setup.scene.material = MaterialParameters{1e5, 0.45, 1e3};
  setup.solver.method = Method::kNewtonCholesky;  // h = 0.01 s by default
  setup.solver.rel_tolerance = 1e-9;
  setup.motion = ReadCapturedMotion(argv[2]);  // markers and samples
  solvers::CalibrationModel model(setup);      // fits {E, nu}; exact forward-mode Jacobian

  double material[2];
  model.InitialMaterialBlock(material);
  solvers::RolloutEvaluationCallback callback(&model, {material});  // one rollout per point
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &callback;
  ceres::Problem problem(problem_options);
  solvers::AddMarkerResidualBlocks(&problem, &model, {material});  // one block per frame
  problem.SetManifold(
      material, new solvers::CoordinateManifold({solvers::CoordinateMap::Log(), solvers::CoordinateMap::Linear()}));
  problem.SetParameterLowerBound(material, 1, 0.01);  // Poisson's ratio in [0.01, 0.49]
  problem.SetParameterUpperBound(material, 1, 0.49);

  ceres::Solver::Options options;
  options.minimizer_progress_to_stdout = true;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  std::printf("%s\nE = %.9g Pa, nu = %.9g (%d rollouts, %.2f s forward, %.2f s derivatives)\n",
              summary.BriefReport().c_str(), material[0], material[1], model.statistics().rollouts,
              model.statistics().forward_seconds, model.statistics().backward_seconds);
  return summary.IsSolutionUsable() ? 0 : 1;
}
