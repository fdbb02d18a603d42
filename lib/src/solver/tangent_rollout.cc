// Forward-mode derivatives of a rollout (Simulator::Tangents).
//
// Implicit methods: the step x_{i+1} = argmin g(x) satisfies
//   grad g = M (x_{i+1} - x_i - h v_i) / h^2 - f + grad E(x_{i+1}; mu, lambda) = 0,
// so, differentiating along a direction,
//   H dx_{i+1} = M (dx_i + h dv_i) / h^2 + df - dmu grad_mu - dlambda grad_lambda
//                - drho [m (x_{i+1} - x_i - h v_i) / h^2 - m g],
// with grad_mu = grad E at (mu, lambda) = (1, 0), grad_lambda likewise, m the
// unit-density lumped mass and g gravity (when declared). All directions share
// the step's H (one StepLinearization, several right-hand sides).
// Semi-implicit Euler: on free DoFs v_{i+1} = v_i + h M^{-1} (f - grad E(x_i)),
//   dv_{i+1} = dv_i + h M^{-1} (df - hess E dx_i - dmu grad_mu - dlambda grad_lambda)
//              - drho (h / rho) M^{-1} (f_user - grad E).
// Both: x_{i+1} is the prescribed value at fixed DoFs (zero tangent there) and
// v_{i+1} = (x_{i+1} - x_i) / h everywhere.
#include <chrono>
#include <cmath>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/tangent_rollout.h"
#include "solver/simulator_impl.h"

namespace diffpd {

InputDirection InputDirection::YoungsModulus() {
  InputDirection d;
  d.youngs_modulus = 1;
  return d;
}

InputDirection InputDirection::PoissonsRatio() {
  InputDirection d;
  d.poissons_ratio = 1;
  return d;
}

InputDirection InputDirection::Density() {
  InputDirection d;
  d.density = 1;
  return d;
}

namespace {

using internal::SimulatorImpl;

void CheckDirectionVector(const VectorXd& v, int n, int p, const char* name) {
  if (v.size() == 0) return;
  if (v.size() != n) {
    std::ostringstream msg;
    msg << "Tangents: direction " << p << " has " << name << " with " << v.size() << " entries, expected " << n
        << " (3 x number of nodes)";
    throw InvalidInputError(msg.str());
  }
  if (!v.allFinite()) {
    std::ostringstream msg;
    msg << "Tangents: direction " << p << " has a non-finite entry in " << name;
    throw InvalidInputError(msg.str());
  }
}

void CheckDirections(const std::vector<InputDirection>& dirs, int n, int steps) {
  if (dirs.empty()) throw InvalidInputError("Tangents: no direction given (need at least one)");
  for (size_t p = 0; p < dirs.size(); ++p) {
    const InputDirection& d = dirs[p];
    const int ip = static_cast<int>(p);
    CheckDirectionVector(d.x0, n, ip, "x0");
    CheckDirectionVector(d.v0, n, ip, "v0");
    if (!d.external_force.empty() && static_cast<int>(d.external_force.size()) != steps) {
      std::ostringstream msg;
      msg << "Tangents: direction " << p << " has external_force for " << d.external_force.size()
          << " steps, expected 0 or " << steps;
      throw InvalidInputError(msg.str());
    }
    for (const VectorXd& f : d.external_force) CheckDirectionVector(f, n, ip, "external_force");
    if (!std::isfinite(d.youngs_modulus) || !std::isfinite(d.poissons_ratio) || !std::isfinite(d.density)) {
      std::ostringstream msg;
      msg << "Tangents: direction " << p << " has a non-finite material component";
      throw InvalidInputError(msg.str());
    }
  }
}

}  // namespace

TangentRollout Simulator::Tangents(const Rollout& rollout, const std::vector<InputDirection>& directions) {
  SimulatorImpl& sim = *impl_;
  const auto start = std::chrono::steady_clock::now();
  const int n = sim.num_dofs();
  const int steps = rollout.num_steps();
  if (static_cast<int>(rollout.states.size()) != steps + 1)
    throw InvalidInputError("Tangents: the rollout has inconsistent states and inputs");
  for (const State& s : rollout.states)
    if (s.x.size() != n || s.v.size() != n)
      throw InvalidInputError("Tangents: the rollout's states do not match the scene's number of DoFs");
  const MaterialParameters& mat = sim.scene.material;
  if (rollout.material.youngs_modulus != mat.youngs_modulus || rollout.material.poissons_ratio != mat.poissons_ratio ||
      rollout.material.density != mat.density || rollout.options.time_step != sim.h() ||
      rollout.options.method != sim.options.method)
    throw InvalidInputError(
        "Tangents: the rollout was made with another material, time step or method than the simulator's current ones");
  CheckDirections(directions, n, steps);

  const int num_dirs = static_cast<int>(directions.size());
  const double h = sim.h();
  const double rho = sim.rho();
  const VectorXd mass = sim.Mass();
  double dmu_dE, dmu_dnu, dl_dE, dl_dnu;
  mat.LameDerivatives(&dmu_dE, &dmu_dnu, &dl_dE, &dl_dnu);
  VectorXd dmu(num_dirs), dlambda(num_dirs), drho(num_dirs);
  for (int p = 0; p < num_dirs; ++p) {
    const InputDirection& d = directions[p];
    dmu(p) = dmu_dE * d.youngs_modulus + dmu_dnu * d.poissons_ratio;
    dlambda(p) = dl_dE * d.youngs_modulus + dl_dnu * d.poissons_ratio;
    drho(p) = d.density;
  }
  const bool need_lame = dmu.any() || dlambda.any();
  VectorXd gravity_unit = VectorXd::Zero(n);
  if (sim.scene.gravity)
    for (int i = 0; i < n / 3; ++i) gravity_unit.segment<3>(3 * i) = sim.unit_mass(3 * i) * (*sim.scene.gravity);

  TangentRollout out;
  out.dx.resize(steps + 1);
  out.dv.resize(steps + 1);
  out.dx[0] = MatrixXd::Zero(n, num_dirs);
  out.dv[0] = MatrixXd::Zero(n, num_dirs);
  for (int p = 0; p < num_dirs; ++p) {
    if (directions[p].x0.size()) out.dx[0].col(p) = directions[p].x0;
    if (directions[p].v0.size()) out.dv[0].col(p) = directions[p].v0;
  }

  VectorXd grad_mu, grad_lambda;
  const bool implicit = sim.options.method != Method::kSemiImplicit;
  for (int i = 0; i < steps; ++i) {
    const State& s0 = rollout.states[i];
    const State& s1 = rollout.states[i + 1];
    const MatrixXd& dx0 = out.dx[i];
    const MatrixXd& dv0 = out.dv[i];
    MatrixXd dx1;
    if (implicit) {
      // Right-hand sides: inertia through xhat, force directions, parameters.
      MatrixXd b = mass.asDiagonal() * (dx0 + h * dv0) / (h * h);
      if (need_lame) {
        sim.elastic.EnergyAndGradient(s1.x, 1.0, 0.0, &grad_mu, sim.threads());
        sim.elastic.EnergyAndGradient(s1.x, 0.0, 1.0, &grad_lambda, sim.threads());
        b -= grad_mu * dmu.transpose() + grad_lambda * dlambda.transpose();
      }
      if (drho.any()) {
        const VectorXd dgrad_drho = sim.unit_mass.cwiseProduct(s1.x - s0.x - h * s0.v) / (h * h) - gravity_unit;
        b -= dgrad_drho * drho.transpose();
      }
      for (int p = 0; p < num_dirs; ++p)
        if (!directions[p].external_force.empty() && directions[p].external_force[i].size())
          b.col(p) += directions[p].external_force[i];
      internal::StepLinearization lin(sim, s1.x);
      dx1 = lin.SolveColumns(b, &out.report);  // zero at fixed DoFs
    } else {
      // Acceleration tangent on free DoFs, then symplectic update.
      std::vector<Mat9> dstress;
      sim.elastic.StressDifferentials(s0.x, sim.mu(), sim.lambda(), &dstress, sim.threads());
      MatrixXd force(n, num_dirs);
      for (int p = 0; p < num_dirs; ++p) {
        VectorXd hdx;
        sim.elastic.ApplyHessian(dstress, dx0.col(p), &hdx, sim.threads());
        force.col(p) = -hdx;
        if (!directions[p].external_force.empty() && directions[p].external_force[i].size())
          force.col(p) += directions[p].external_force[i];
      }
      if (need_lame) {
        sim.elastic.EnergyAndGradient(s0.x, 1.0, 0.0, &grad_mu, sim.threads());
        sim.elastic.EnergyAndGradient(s0.x, 0.0, 1.0, &grad_lambda, sim.threads());
        force -= grad_mu * dmu.transpose() + grad_lambda * dlambda.transpose();
      }
      MatrixXd dv1 = dv0 + h * mass.cwiseInverse().asDiagonal() * force;
      if (drho.any()) {
        VectorXd grad_e;
        sim.elastic.EnergyAndGradient(s0.x, sim.mu(), sim.lambda(), &grad_e, sim.threads());
        const VectorXd& user = rollout.inputs[i].external_force;
        const VectorXd net = (user.size() ? user : VectorXd::Zero(n)) - grad_e;
        dv1 -= (h / rho) * net.cwiseQuotient(mass) * drho.transpose();
      }
      dx1 = dx0 + h * dv1;
      for (int d = 0; d < n; ++d)
        if (sim.fixed[d]) dx1.row(d).setZero();
    }
    out.dv[i + 1] = (dx1 - dx0) / h;
    out.dx[i + 1] = std::move(dx1);
  }
  out.report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace diffpd
