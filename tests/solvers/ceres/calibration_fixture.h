// A small synthetic calibration shared by the Ceres adapter tests: a clamped
// beam swinging under gravity with an initial sideways velocity, captured
// markers (three vertices and one element point) sampled at frames that do
// not align with the simulation steps.
#pragma once

#include <memory>
#include <vector>

#include <ceres/ceres.h>

#include "diffpd/captured_motion.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/ceres/coordinate_manifold.h"
#include "diffpd/solvers/ceres/rollout_cost_function.h"
#include "diffpd/solvers/ceres/rollout_evaluation_callback.h"
#include "diffpd/solvers/core/marker_residuals.h"
#include "diffpd/solvers/core/material_block.h"
#include "diffpd/solvers/core/rollout_function.h"
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

// Initial state: rest, with a sideways velocity growing along the beam.
inline State SwingStart(const Simulator& sim) {
  State s = sim.RestState();
  for (int i = 0; i < s.x.size() / 3; ++i) s.v(3 * i + 1) = 2.0 * s.x(3 * i);
  return s;
}

// What a synthetic calibration is made from: the scene (whose materials are
// the fit's starting values), the simulator settings, the captured motion,
// the initial state and the number of steps.
struct SyntheticCalibration {
  Scene scene;
  SolverOptions options;
  CapturedMotion motion;
  State start;
  int steps = 0;

  // The rollout function of the fit: a MaterialBlock of `entries` (block 0)
  // and the marker residuals (functional 0).
  std::unique_ptr<solvers::RolloutFunction> MakeFunction(
      const std::vector<solvers::MaterialBlock::Entry>& entries) const {
    auto f = std::make_unique<solvers::RolloutFunction>(scene, options, steps);
    f->SetInitialState(start);
    f->AddBlock(std::make_unique<solvers::MaterialBlock>(entries, scene));
    f->AddFunctional(std::make_unique<solvers::MarkerResiduals>(motion, scene.mesh, options.time_step, steps));
    return f;
  }
};

// Motion synthesised from `truth_scene` (its materials, base and regions, are
// the truth) over `steps` steps of 0.01 s, frames every 0.015 s, noise-free
// unless `noise` (m) > 0; per-axis weights 1e3 (mm-scale residuals), the y
// axis (the swing) counted twice. The scene is the truth: set the starting
// materials on it.
inline SyntheticCalibration SyntheticFromScene(const Scene& truth_scene, Method method, int steps = 8,
                                               double noise = 0) {
  SyntheticCalibration c;
  c.scene = truth_scene;
  c.options = CalibrationSolverOptions(method);
  c.steps = steps;
  Simulator truth(c.scene, c.options);
  c.start = SwingStart(truth);
  const Rollout rollout = truth.Simulate(c.start, std::vector<StepInput>(steps));
  const Mesh& mesh = c.scene.mesh;
  int far = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (mesh.vertices(0, v) > mesh.vertices(0, far) + 1e-9) far = v;
  const bool tets = mesh.type == ElementType::kTet4;
  std::vector<diffpd::Marker> markers;
  markers.push_back(diffpd::Marker{0, far, -1, Vec3::Zero(), 0});
  markers.push_back(diffpd::Marker{1, far - 1, -1, Vec3::Zero(), 0});
  markers.push_back(diffpd::Marker{5, mesh.num_vertices() / 2, -1, Vec3::Zero(), 0});
  markers.push_back(
      diffpd::Marker{7, -1, mesh.num_elements() - 1, tets ? Vec3(0.2, 0.3, 0.1) : Vec3(0.5, -0.25, 0.75), 0});
  std::vector<double> times;
  for (double t = 0.015; t <= steps * 0.01 + 1e-12; t += 0.015) times.push_back(t);
  c.motion = SampleMarkers(mesh, rollout.states, c.options.time_step, markers, times, noise, 2021);
  for (MarkerSample& s : c.motion.samples) s.weight = Vec3(1e3, 2e3, 1e3);
  return c;
}

// Motion synthesised from TrueMaterial() on SmallBeamScene(tets) (see
// SyntheticFromScene), and the scene's material set to `start`.
inline SyntheticCalibration Synthetic(Method method, bool tets, const MaterialParameters& start, int steps = 8,
                                      double noise = 0) {
  Scene scene = SmallBeamScene(tets);
  scene.material = TrueMaterial();
  SyntheticCalibration c = SyntheticFromScene(scene, method, steps, noise);
  c.scene.material = start;
  return c;
}

// {E, nu} of the base material.
inline std::vector<solvers::MaterialBlock::Entry> YoungsModulusAndPoissonsRatio() {
  return {solvers::MaterialField::kYoungsModulus, solvers::MaterialField::kPoissonsRatio};
}

// Fits block 0 (a MaterialBlock) of `f` from its starting values with
// TightRecoveryOptions: the marker residuals (functional 0) in one residual
// block, E and density in log space, Poisson's ratios linear within
// [0.05, 0.49]. Returns the block.
inline std::vector<double> FitMaterialBlock(solvers::RolloutFunction* f, ceres::Solver::Summary* summary) {
  const auto& block = dynamic_cast<const solvers::MaterialBlock&>(f->block(0));
  std::vector<double> material(block.initial().data(), block.initial().data() + block.size());
  std::vector<solvers::CoordinateMap> maps;
  for (const solvers::MaterialBlock::Entry& e : block.entries())
    maps.push_back(e.field == solvers::MaterialField::kPoissonsRatio ? solvers::CoordinateMap::Linear()
                                                                     : solvers::CoordinateMap::Log());
  solvers::RolloutEvaluationCallback callback(f, {material.data()});
  ceres::Problem::Options po;
  po.evaluation_callback = &callback;
  ceres::Problem problem(po);
  solvers::AddMarkerResidualBlocks(&problem, f, 0, {material.data()}, solvers::ResidualBlocks::kSingle);
  problem.SetManifold(material.data(), new solvers::CoordinateManifold(maps));
  for (size_t i = 0; i < maps.size(); ++i)
    if (block.entries()[i].field == solvers::MaterialField::kPoissonsRatio) {
      problem.SetParameterLowerBound(material.data(), static_cast<int>(i), 0.05);
      problem.SetParameterUpperBound(material.data(), static_cast<int>(i), 0.49);
    }
  ceres::Solve(TightRecoveryOptions(), &problem, summary);
  return material;
}

}  // namespace diffpd::testing
