// Small trajectory-optimisation instances shared by the Ipopt adapter tests.
#pragma once

#include <memory>
#include <vector>

#include "diffpd/simulator.h"
#include "diffpd/solvers/core/control_signal.h"
#include "diffpd/solvers/control_variables.h"
#include "diffpd/solvers/linear_constraint.h"
#include "diffpd/solvers/rollout_nlp.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "test_scenes.h"

namespace diffpd::testing {

// Nodes with x >= max x - tol.
inline std::vector<int> NodesAtXMax(const Mesh& mesh, double tol = 1e-9) {
  const double xmax = mesh.vertices.row(0).maxCoeff();
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.vertices(0, i) >= xmax - tol) nodes.push_back(i);
  return nodes;
}

// Newton-Cholesky converged far below finite-difference noise.
inline SolverOptions TightNewton(double h = 0.01) {
  SolverOptions o;
  o.method = Method::kNewtonCholesky;
  o.time_step = h;
  o.abs_tolerance = 1e-12;
  o.rel_tolerance = 1e-13;
  o.num_threads = 1;
  return o;
}

inline SolverOptions TightPd(double h = 0.01) {
  SolverOptions o = TightNewton(h);
  o.method = Method::kPd;
  o.max_iterations = 5000;
  return o;
}

inline solvers::RolloutSetup RestSetup(const Simulator& sim, int steps) {
  solvers::RolloutSetup s;
  s.initial = sim.RestState();
  s.inputs.resize(steps);
  s.material = sim.scene().material;
  return s;
}

// The clamped beam of SmallBeamScene driven at its tip by every kind of
// variable block and constrained by every kind of constraint:
//  variables: forces on the tip nodes along z (one per step), along y
//    (piecewise linear, 3 knots), along x (sinusoid with offset, amplitude,
//    phase); a shared initial velocity of the tip nodes; per-node initial
//    positions of two tip nodes; Young's modulus and density (scaled);
//  objective: 1e3 |tip marker at K - target|^2 + 1e-2/2 |forces|^2;
//  constraints: tip z at state 2 (path), the clamp-to-tip axis alignment
//    with z at K, the centre of mass's x travel 0 -> K, and one linear row.
struct BeamNlp {
  static constexpr int kSteps = 5;
  std::unique_ptr<Simulator> sim;
  Ipopt::SmartPtr<solvers::RolloutNlp> nlp;
  std::vector<int> tip;
  int force_offset = 0, velocity_offset = 0, position_offset = 0, material_offset = 0;
  int num_force_variables = 0;

  explicit BeamNlp(const SolverOptions& options) {
    using namespace solvers;
    sim = std::make_unique<Simulator>(SmallBeamScene(), options);
    const Mesh& mesh = sim->scene().mesh;
    const int n = mesh.num_vertices();
    const double h = options.time_step;
    tip = NodesAtXMax(mesh);
    nlp = new RolloutNlp(sim.get(), RestSetup(*sim, kSteps));

    std::vector<ExternalForceControl::Channel> channels(3);
    channels[0] = {tip, Vec3::UnitZ(), std::make_unique<PerStepSignal>(kSteps)};
    channels[1] = {tip, Vec3::UnitY(), std::make_unique<PiecewiseLinearSignal>(kSteps, 3)};
    channels[2] = {tip, Vec3::UnitX(), std::make_unique<SinusoidSignal>(kSteps, h, 4 * h)};
    auto forces = std::make_unique<ExternalForceControl>(std::move(channels));
    num_force_variables = forces->size();
    VectorXd f0(forces->size());
    f0 << 0.02, -0.01, 0.03, 0.0, 0.01, 0.01, -0.02, 0.015, 0.005, 0.02, 0.7;
    forces->SetInitial(f0);
    forces->SetBounds(-0.5, 0.5);
    forces->SetBounds(10, 1, -M_PI, M_PI);  // the sinusoid's phase
    force_offset = nlp->AddVariables(std::move(forces));

    auto velocity = std::make_unique<InitialStateVariables>(InitialStateVariables::kVelocity, tip);
    velocity->SetInitial(Vec3(0.01, -0.02, 0.05));
    velocity_offset = nlp->AddVariables(std::move(velocity));

    auto position = std::make_unique<InitialStateVariables>(
        InitialStateVariables::kPosition, std::vector<int>{tip[0], tip[1]}, InitialStateVariables::kPerNode);
    VectorXd p0(6);
    p0 << 1e-3, 0, -2e-3, 0, 1e-3, 5e-4;
    position->SetInitial(p0);
    position_offset = nlp->AddVariables(std::move(position));

    auto material = std::make_unique<MaterialVariables>(
        std::vector<MaterialVariables::Entry>{{MaterialVariables::kYoungsModulus, 1e5},
                                              {MaterialVariables::kDensity, 1e3}},
        sim->scene().material);
    material->SetBounds(0.5, 5.0);
    material_offset = nlp->AddVariables(std::move(material));

    const TrackedPoint marker = NodePoint(n, tip.back());
    nlp->AddObjective(std::make_unique<PointDistanceSquared>(marker, kFinalState,
                                                             marker.At(sim->RestState().x) + Vec3(0.0, 0.01, 0.02)),
                      1e3);
    nlp->AddRegularization(force_offset, num_force_variables, 1e-2);
    nlp->AddConstraint(std::make_unique<PointCoordinate>(marker, 2, Vec3::UnitZ(), "tip_z_at_2"), -1.0, 1.0);
    nlp->AddConstraint(
        std::make_unique<AxisAlignment>(MeanOf(n, NodesAtXMin(mesh)), MeanOf(n, tip), kFinalState, Vec3(0.1, 0.0, 1.0)),
        -1.0, 1.0);
    nlp->AddConstraint(std::make_unique<PointTravel>(CentreOfMass(sim->LumpedMass()), 0, kFinalState, Vec3::UnitX()),
                       -0.1, 0.1);
    LinearConstraint row;
    row.columns = {force_offset + 0, force_offset + 6};
    row.coefficients = {1.0, -2.0};
    row.upper = 1.0;
    nlp->AddLinearConstraint(row);
  }
};

}  // namespace diffpd::testing
