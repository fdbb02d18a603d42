// Small trajectory-optimisation instances shared by the Ipopt adapter tests.
#pragma once

#include <memory>
#include <vector>

#include "diffpd/simulator.h"
#include "diffpd/solvers/core/control_signal.h"
#include "diffpd/solvers/core/external_force_block.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "diffpd/solvers/core/material_block.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "diffpd/solvers/ipopt/linear_constraint.h"
#include "diffpd/solvers/ipopt/rollout_nlp.h"
#include "solvers/core/parameter_block_cases.h"  // NodesAtXMax
#include "test_scenes.h"

namespace diffpd::testing {

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

// An NLP over `steps` steps of `scene` from rest, without variables yet.
inline Ipopt::SmartPtr<solvers::RolloutNlp> EmptyNlp(const Scene& scene, const SolverOptions& options, int steps) {
  return new solvers::RolloutNlp(std::make_unique<solvers::RolloutFunction>(scene, options, steps));
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
  Ipopt::SmartPtr<solvers::RolloutNlp> nlp;
  const Simulator* sim = nullptr;  // the NLP's
  std::vector<int> tip;
  int force_offset = 0, velocity_offset = 0, position_offset = 0, material_offset = 0;
  int num_force_variables = 0;

  explicit BeamNlp(const SolverOptions& options) {
    using namespace solvers;
    const Scene scene = SmallBeamScene();
    nlp = EmptyNlp(scene, options, kSteps);
    sim = &nlp->function().simulator();
    const Mesh& mesh = scene.mesh;
    const int n = mesh.num_vertices();
    const double h = options.time_step;
    tip = NodesAtXMax(mesh);

    std::vector<ExternalForceBlock::Channel> channels(3);
    channels[0] = {tip, Vec3::UnitZ(), std::make_unique<PerStepSignal>(kSteps)};
    channels[1] = {tip, Vec3::UnitY(), std::make_unique<PiecewiseLinearSignal>(kSteps, 3)};
    channels[2] = {tip, Vec3::UnitX(), std::make_unique<SinusoidSignal>(kSteps, h, 4 * h)};
    auto forces = std::make_unique<ExternalForceBlock>(std::move(channels));
    num_force_variables = forces->size();
    VectorXd f0(forces->size());
    f0 << 0.02, -0.01, 0.03, 0.0, 0.01, 0.01, -0.02, 0.015, 0.005, 0.02, 0.7;
    forces->SetInitial(f0);
    forces->SetBounds(-0.5, 0.5);
    forces->SetBounds(10, 1, -M_PI, M_PI);  // the sinusoid's phase
    force_offset = nlp->AddVariables(std::move(forces));

    auto velocity = std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, tip);
    velocity->SetInitial(Vec3(0.01, -0.02, 0.05));
    velocity_offset = nlp->AddVariables(std::move(velocity));

    auto position = std::make_unique<InitialStateBlock>(InitialStateBlock::kPosition, std::vector<int>{tip[0], tip[1]},
                                                        InitialStateBlock::kPerNode);
    VectorXd p0(6);
    p0 << 1e-3, 0, -2e-3, 0, 1e-3, 5e-4;
    position->SetInitial(p0);
    position_offset = nlp->AddVariables(std::move(position));

    auto material = std::make_unique<MaterialBlock>(
        std::vector<MaterialBlock::Entry>{{MaterialField::kYoungsModulus, kBaseMaterial, 1e5},
                                          {MaterialField::kDensity, kBaseMaterial, 1e3}},
        scene);
    material->SetBounds(0.5, 5.0);
    material_offset = nlp->AddVariables(std::move(material));

    const TrackedPoint marker = NodePoint(n, tip.back());
    const VectorXd rest = sim->RestState().x;
    nlp->AddObjective(
        std::make_unique<PointDistanceSquared>(marker, kFinalState, marker.At(rest) + Vec3(0.0, 0.01, 0.02)), 1e3);
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
