// One small rollout function per kind of parameter block, shared by the
// derivative checks of the core (central differences), of the Ceres adapter
// (ceres::GradientChecker) and of the Ipopt adapter (Ipopt's derivative_test):
// every block is checked once, here, and each adapter runs its own checker on
// the same cases.
//
// Each case simulates 5 steps of 0.01 s with Newton-Cholesky converged far
// below the differences' noise, and evaluates the same probe rows: a tip
// coordinate at state 2 (a path row: later inputs do not affect it), the
// squared distance of the tip to a target at K, the tilt of the body axis at
// K and the squared speed of a tip node at state 3 (a row that reads
// velocities); the material case adds captured-marker residuals.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "diffpd/captured_motion.h"
#include "diffpd/solvers/core/activation_block.h"
#include "diffpd/solvers/core/external_force_block.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "diffpd/solvers/core/linear_input_block.h"
#include "diffpd/solvers/core/marker_residuals.h"
#include "diffpd/solvers/core/material_block.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "diffpd/solvers/core/state_force_block.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "diffpd/state_forces.h"
#include "test_scenes.h"

namespace diffpd::testing {

// |v_node(k)|^2 (m^2/s^2): a probe that reads velocities.
class NodeSpeedSquared : public solvers::TrajectoryFunction {
 public:
  NodeSpeedSquared(int node, int step) : node_(node), step_(step) {}
  std::string name() const override { return "node_speed_squared"; }
  int LastState(int num_steps) const override { return step_; }
  double Value(const Rollout& r) const override { return r.states[step_].v.segment<3>(3 * node_).squaredNorm(); }
  void AddGradient(const Rollout& r, double weight, LossGradient* loss) const override {
    VectorXd& dv = loss->dv[step_];
    if (dv.size() == 0) dv = VectorXd::Zero(r.states[step_].v.size());
    dv.segment<3>(3 * node_) += 2 * weight * r.states[step_].v.segment<3>(3 * node_);
  }

 private:
  int node_, step_;
};

struct ParameterBlockCase {
  std::unique_ptr<solvers::RolloutFunction> function;
  VectorXd point;    // where to check (inside every block's domain)
  VectorXd typical;  // a typical magnitude per parameter (central-difference steps are 1e-3 of it)
};

// Nodes with x >= max x - tol.
inline std::vector<int> NodesAtXMax(const Mesh& mesh, double tol = 1e-9) {
  const double xmax = mesh.vertices.row(0).maxCoeff();
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.vertices(0, i) >= xmax - tol) nodes.push_back(i);
  return nodes;
}

inline SolverOptions CaseOptions() {
  SolverOptions o = TightOptions(Method::kNewtonCholesky);
  o.time_step = 0.01;
  return o;
}

// The probe rows of the file comment.
inline void AddProbes(solvers::RolloutFunction* f) {
  using namespace solvers;
  const Mesh& mesh = f->scene().mesh;
  const int n = mesh.num_vertices();
  const std::vector<int> tip = NodesAtXMax(mesh);
  std::vector<int> back;
  const double xmin = mesh.vertices.row(0).minCoeff();
  for (int i = 0; i < n; ++i)
    if (mesh.vertices(0, i) <= xmin + 1e-9) back.push_back(i);
  const TrackedPoint marker = NodePoint(n, tip.back());
  const VectorXd rest = Eigen::Map<const VectorXd>(mesh.vertices.data(), 3 * n);
  f->AddFunctional(std::make_unique<PointCoordinate>(marker, 2, Vec3(0.2, 0.5, 1.0), "tip_at_2"));
  f->AddFunctional(std::make_unique<PointDistanceSquared>(MeanOf(n, tip), kFinalState,
                                                          MeanOf(n, tip).At(rest) + Vec3(0.01, 0.02, 0.01)));
  f->AddFunctional(std::make_unique<AxisAlignment>(MeanOf(n, back), MeanOf(n, tip), kFinalState, Vec3(1, 0.1, 0.2)));
  f->AddFunctional(std::make_unique<NodeSpeedSquared>(tip.front(), 3));
}

// Initial positions of two tip nodes (per node) and the tip's velocity (shared).
inline ParameterBlockCase InitialStateCase() {
  using namespace solvers;
  ParameterBlockCase c;
  c.function = std::make_unique<RolloutFunction>(SmallBeamScene(), CaseOptions(), 5);
  const std::vector<int> tip = NodesAtXMax(c.function->scene().mesh);
  c.function->AddBlock(std::make_unique<InitialStateBlock>(
      InitialStateBlock::kPosition, std::vector<int>{tip[0], tip[1]}, InitialStateBlock::kPerNode));
  c.function->AddBlock(std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, tip));
  AddProbes(c.function.get());
  c.point.resize(9);
  c.point << 1e-3, 0, -2e-3, 0, 1e-3, 5e-4, 0.01, -0.02, 0.05;
  c.typical = VectorXd::Constant(9, 0.05);
  c.typical.head(6).setConstant(1e-2);
  return c;
}

// A shear of the initial positions, a spin of the initial velocities and a
// force held over steps 1..3, with two parameters.
inline ParameterBlockCase LinearInputCase() {
  using namespace solvers;
  ParameterBlockCase c;
  const Scene scene = SmallBeamScene();
  c.function = std::make_unique<RolloutFunction>(scene, CaseOptions(), 5);
  const int n = scene.mesh.num_dofs();
  MatrixXd xb = MatrixXd::Zero(n, 2), vb = MatrixXd::Zero(n, 2), fb = MatrixXd::Zero(n, 2);
  for (int i = 0; i < n / 3; ++i) {
    const double x = scene.mesh.vertices(0, i);
    xb(3 * i + 2, 0) = 0.1 * x;
    vb(3 * i + 1, 1) = x;
    fb(3 * i + 2, 1) = -0.01;
  }
  c.function->AddBlock(std::make_unique<LinearInputBlock>(xb, vb, fb, 1, 4));
  AddProbes(c.function.get());
  c.point = Eigen::Vector2d(0.02, -0.3);
  c.typical = Eigen::Vector2d(0.02, 0.3);
  return c;
}

// Tip forces along z (per step), y (piecewise linear, 3 knots) and x
// (sinusoid: offset, amplitude, phase).
inline ParameterBlockCase ExternalForceCase() {
  using namespace solvers;
  ParameterBlockCase c;
  c.function = std::make_unique<RolloutFunction>(SmallBeamScene(), CaseOptions(), 5);
  const std::vector<int> tip = NodesAtXMax(c.function->scene().mesh);
  std::vector<ExternalForceBlock::Channel> channels(3);
  channels[0] = {tip, Vec3::UnitZ(), std::make_unique<PerStepSignal>(5)};
  channels[1] = {tip, Vec3::UnitY(), std::make_unique<PiecewiseLinearSignal>(5, 3)};
  channels[2] = {tip, Vec3::UnitX(), std::make_unique<SinusoidSignal>(5, 0.01, 0.04)};
  c.function->AddBlock(std::make_unique<ExternalForceBlock>(std::move(channels)));
  AddProbes(c.function.get());
  c.point.resize(11);
  c.point << 0.02, -0.01, 0.03, 0.0, 0.01, 0.01, -0.02, 0.015, 0.005, 0.02, 0.7;
  c.typical = VectorXd::Constant(11, 0.02);
  c.typical(10) = 1.0;  // the phase
  return c;
}

// Two muscles (upper and lower half of the beam, fibres along x): one
// per-step channel, one Fourier channel.
inline ParameterBlockCase ActivationCase() {
  using namespace solvers;
  ParameterBlockCase c;
  Scene scene = SmallBeamScene();
  Muscle upper, lower;
  for (int e = 0; e < scene.mesh.num_elements(); ++e) {
    double z = 0;
    for (int a = 0; a < 8; ++a) z += scene.mesh.vertices(2, scene.mesh.elements(a, e)) / 8;
    (z > 0.02 ? upper : lower).elements.push_back(e);
  }
  upper.fibers = lower.fibers = {Vec3::UnitX()};
  upper.stiffness = lower.stiffness = 1e5;
  scene.muscles = {upper, lower};
  c.function = std::make_unique<RolloutFunction>(scene, CaseOptions(), 5);
  std::vector<ActivationBlock::Channel> channels(2);
  channels[0] = {0, std::make_unique<PerStepSignal>(5)};
  channels[1] = {1, std::make_unique<FourierSignal>(5, 0.01, 0.04, 1)};
  c.function->AddBlock(std::make_unique<ActivationBlock>(std::move(channels)));
  AddProbes(c.function.get());
  c.point.resize(8);
  c.point << 0.9, 0.95, 1.0, 0.85, 0.92, 1.0, 0.05, -0.03;
  c.typical = VectorXd::Constant(8, 0.5);
  return c;
}

// The two-region beam: base E, nu, rho and region 0's E and nu, region 1's
// rho, scaled, with captured-marker residuals of a motion made at other
// materials as well as the probes.
inline ParameterBlockCase MaterialCase() {
  using namespace solvers;
  ParameterBlockCase c;
  const Scene scene = TwoRegionBeamScene();
  const SolverOptions options = CaseOptions();
  c.function = std::make_unique<RolloutFunction>(scene, options, 5);
  State start = c.function->simulator().RestState();
  for (int i = 0; i < start.x.size() / 3; ++i) start.v(3 * i + 1) = 2.0 * start.x(3 * i);
  c.function->SetInitialState(start);
  c.function->AddBlock(std::make_unique<MaterialBlock>(
      std::vector<MaterialBlock::Entry>{{MaterialField::kYoungsModulus, kBaseMaterial, 1e5},
                                        MaterialField::kPoissonsRatio,
                                        {MaterialField::kDensity, kBaseMaterial, 1e3},
                                        {MaterialField::kYoungsModulus, 0, 1e5},
                                        {MaterialField::kPoissonsRatio, 0},
                                        {MaterialField::kDensity, 1, 1e3}},
      scene));
  AddProbes(c.function.get());
  // Markers of the truth (the scene itself) at frames between steps.
  Simulator truth(scene, options);
  const Rollout r = truth.Simulate(start, std::vector<StepInput>(5));
  const int far = NodesAtXMax(scene.mesh).back();
  std::vector<diffpd::Marker> markers = {
      diffpd::Marker{0, far, -1, Vec3::Zero(), 0},
      diffpd::Marker{3, -1, scene.mesh.num_elements() - 1, Vec3(0.5, -0.25, 0.75), 0}};
  const CapturedMotion motion = SampleMarkers(scene.mesh, r.states, 0.01, markers, {0.015, 0.03, 0.045});
  c.function->AddFunctional(std::make_unique<MarkerResiduals>(motion, scene.mesh, 0.01, 5));
  c.point.resize(6);
  c.point << 1.7, 0.37, 1.1, 0.6, 0.32, 0.9;
  c.typical = c.point;
  return c;
}

// A free box swimming in a current, damped, sliding on a penalty floor with
// friction, thrown sideways: every state-force parameter, and the throw.
inline ParameterBlockCase StateForceCase() {
  using namespace solvers;
  ParameterBlockCase c;
  Scene scene;
  scene.mesh = BoxHexMesh(2, 2, 1, 0.1, 0.1, 0.05);
  scene.material = MaterialParameters{1e5, 0.4, 800};
  scene.gravity = Vec3(0, 0, -9.81);
  Hydrodynamics hydro;
  hydro.triangles = BoundaryTriangles(scene.mesh);
  hydro.thrust = 0.6;
  hydro.flow_velocity = Vec3(0.1, -0.05, 0.02);
  scene.hydrodynamics = hydro;
  scene.linear_damping = 0.5;
  PenaltyContact floor;
  floor.offset = 0.002;  // the bottom nodes start 2 mm inside
  floor.stiffness = 200;
  floor.friction = 0.4;
  floor.friction_velocity = 0.05;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) < 1e-9) floor.nodes.push_back(i);
  scene.penalty_contacts = {floor};
  c.function = std::make_unique<RolloutFunction>(scene, CaseOptions(), 5);
  std::vector<int> all(scene.mesh.num_vertices());
  for (int i = 0; i < scene.mesh.num_vertices(); ++i) all[i] = i;
  c.function->AddBlock(std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, all));
  c.function->AddBlock(
      std::make_unique<StateForceBlock>(std::vector<StateForceBlock::Entry>{StateForceField::kLinearDamping,
                                                                            {StateForceField::kFluidDensity, 1e3},
                                                                            StateForceField::kDragTangential,
                                                                            StateForceField::kDragNormal,
                                                                            StateForceField::kThrust,
                                                                            StateForceField::kFlowVelocityX,
                                                                            StateForceField::kFlowVelocityY,
                                                                            StateForceField::kFlowVelocityZ,
                                                                            {StateForceField::kPenaltyFriction, 1, 0}},
                                        scene));
  AddProbes(c.function.get());
  c.point.resize(12);
  c.point << 0.2, 0.1, 0.05, 0.6, 1.1, 0.07, 1.8, 0.5, 0.12, -0.04, 0.03, 0.35;
  c.typical = c.point.cwiseAbs().cwiseMax(0.05);
  return c;
}

inline std::vector<std::string> ParameterBlockCaseNames() {
  return {"initial_state", "linear_input", "external_force", "activation", "material", "state_forces"};
}

// Throws std::invalid_argument for an unknown name.
inline ParameterBlockCase MakeParameterBlockCase(const std::string& name) {
  if (name == "initial_state") return InitialStateCase();
  if (name == "linear_input") return LinearInputCase();
  if (name == "external_force") return ExternalForceCase();
  if (name == "activation") return ActivationCase();
  if (name == "material") return MaterialCase();
  if (name == "state_forces") return StateForceCase();
  throw std::invalid_argument("unknown parameter block case '" + name + "'");
}

}  // namespace diffpd::testing
