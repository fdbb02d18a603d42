// A small synthetic calibration shared by the Ceres adapter tests: a clamped
// beam swinging under gravity with an initial sideways velocity, captured
// markers (three vertices and one element point) sampled at frames that do
// not align with the simulation steps.
#pragma once

#include <vector>

#include <ceres/ceres.h>

#include "diffpd/captured_motion.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/calibration_model.h"
#include "diffpd/solvers/coordinate_manifold.h"
#include "diffpd/solvers/marker_cost_function.h"
#include "test_scenes.h"

namespace diffpd::testing {

// The true material of the synthetic captures.
inline MaterialParameters TrueMaterial() { return MaterialParameters{2e5, 0.4, 1e3}; }

inline SolverOptions CalibrationSolverOptions(Method method) {
  SolverOptions options = TightOptions(method);
  options.time_step = 0.01;
  options.backward_rel_tolerance = 1e-12;
  return options;
}

// Ceres settings of the noise-free recovery tests: converged far below the
// recovery tolerances (1e-6 relative).
inline ceres::Solver::Options TightRecoveryOptions() {
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.gradient_tolerance = 1e-16;
  return options;
}

// Fits the material block of `setup` (from its starting values) with
// TightRecoveryOptions: marker residuals in one block, E and density in log
// space, Poisson's ratios linear within [0.05, 0.49]. Returns the block.
inline std::vector<double> FitMaterialBlock(const solvers::CalibrationSetup& setup, ceres::Solver::Summary* summary) {
  solvers::CalibrationModel model(setup);
  std::vector<double> material(model.parameter_block_sizes()[0]);
  model.InitialMaterialBlock(material.data());
  std::vector<solvers::MaterialParameter> kinds = setup.fitted;
  for (const solvers::RegionParameter& rp : setup.fitted_regions) kinds.push_back(rp.parameter);
  std::vector<solvers::CoordinateMap> maps;
  for (const solvers::MaterialParameter p : kinds)
    maps.push_back(p == solvers::MaterialParameter::kPoissonsRatio ? solvers::CoordinateMap::Linear()
                                                                   : solvers::CoordinateMap::Log());
  solvers::RolloutEvaluationCallback callback(&model, {material.data()});
  ceres::Problem::Options po;
  po.evaluation_callback = &callback;
  ceres::Problem problem(po);
  solvers::AddMarkerResidualBlocks(&problem, &model, {material.data()}, solvers::ResidualBlocks::kSingle);
  problem.SetManifold(material.data(), new solvers::CoordinateManifold(maps));
  for (size_t i = 0; i < kinds.size(); ++i)
    if (kinds[i] == solvers::MaterialParameter::kPoissonsRatio) {
      problem.SetParameterLowerBound(material.data(), static_cast<int>(i), 0.05);
      problem.SetParameterUpperBound(material.data(), static_cast<int>(i), 0.49);
    }
  ceres::Solve(TightRecoveryOptions(), &problem, summary);
  return material;
}

// Initial state: rest, with a sideways velocity growing along the beam.
inline State SwingStart(const Simulator& sim) {
  State s = sim.RestState();
  for (int i = 0; i < s.x.size() / 3; ++i) s.v(3 * i + 1) = 2.0 * s.x(3 * i);
  return s;
}

// Setup with motion synthesised from the scene `truth` (its materials, base
// and regions, are the truth) over `steps` steps of 0.01 s, frames every
// 0.015 s, noise-free unless `noise` (m) > 0. setup.scene is `truth`: set
// the starting materials on it.
inline solvers::CalibrationSetup SyntheticSetupFromScene(const Scene& truth_scene, Method method, int steps = 8,
                                                         double noise = 0) {
  const Scene& scene = truth_scene;
  const SolverOptions options = CalibrationSolverOptions(method);
  Simulator truth(scene, options);
  const State start_state = SwingStart(truth);
  const Rollout rollout = truth.Simulate(start_state, std::vector<StepInput>(steps));
  std::vector<Marker> markers;
  int far = 0;
  for (int v = 0; v < scene.mesh.num_vertices(); ++v)
    if (scene.mesh.vertices(0, v) > scene.mesh.vertices(0, far) + 1e-9) far = v;
  const bool tets = scene.mesh.type == ElementType::kTet4;
  markers.push_back(Marker{0, far, -1, Vec3::Zero(), 0});
  markers.push_back(Marker{1, far - 1, -1, Vec3::Zero(), 0});
  markers.push_back(Marker{5, scene.mesh.num_vertices() / 2, -1, Vec3::Zero(), 0});
  markers.push_back(
      Marker{7, -1, scene.mesh.num_elements() - 1, tets ? Vec3(0.2, 0.3, 0.1) : Vec3(0.5, -0.25, 0.75), 0});
  std::vector<double> times;
  for (double t = 0.015; t <= steps * 0.01 + 1e-12; t += 0.015) times.push_back(t);
  solvers::CalibrationSetup setup;
  setup.motion = SampleMarkers(scene.mesh, rollout.states, options.time_step, markers, times, noise, 2021);
  // Per-axis weights: mm-scale residuals, the y axis (the swing) counted twice.
  for (MarkerSample& s : setup.motion.samples) s.weight = Vec3(1e3, 2e3, 1e3);
  setup.scene = scene;
  setup.solver = options;
  setup.initial = start_state;
  setup.num_steps = steps;
  return setup;
}

// Setup with motion synthesised from TrueMaterial() on SmallBeamScene(tets)
// (see SyntheticSetupFromScene), and the scene's material set to `start`.
inline solvers::CalibrationSetup SyntheticSetup(Method method, bool tets, const MaterialParameters& start,
                                                int steps = 8, double noise = 0) {
  Scene scene = SmallBeamScene(tets);
  scene.material = TrueMaterial();
  solvers::CalibrationSetup setup = SyntheticSetupFromScene(scene, method, steps, noise);
  setup.scene.material = start;
  return setup;
}

}  // namespace diffpd::testing
