#include "solver/simulator_impl.h"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "diffpd/error.h"
#include "scene/material_regions.h"

namespace diffpd::internal {

SimulatorImpl::SimulatorImpl(const Scene& scene_in, const SolverOptions& options_in)
    : scene((scene_in.Validate(), scene_in)),
      options((options_in.Validate(), options_in)),
      fem(scene.mesh, scene.mass_lumping),
      part_of_element(PartOfElement(scene)),
      mass_model(fem, part_of_element, num_parts()),
      elastic(fem, scene.energies),
      aux(fem, scene),
      state_forces(scene) {
  const int n = scene.mesh.num_dofs();
  fixed.assign(n, 0);
  fixed_values = VectorXd::Zero(n);
  for (size_t k = 0; k < scene.dirichlet.dofs.size(); ++k) {
    fixed[scene.dirichlet.dofs[k]] = 1;
    fixed_values(scene.dirichlet.dofs[k]) = scene.dirichlet.values(k);
  }
  rest_extent = (scene.mesh.vertices.rowwise().maxCoeff() - scene.mesh.vertices.rowwise().minCoeff()).norm();
  MaterialsChanged();
}

void SimulatorImpl::SetMaterial(const MaterialParameters& material) {
  scene.material = material;
  MaterialsChanged();
}

void SimulatorImpl::SetRegionMaterial(int region, const MaterialParameters& material) {
  DIFFPD_CHECK(region >= 0 && region < num_parts() - 1, "material region " << region << " out of range");
  scene.material_regions[region].material = material;
  MaterialsChanged();
}

void SimulatorImpl::MaterialsChanged() {
  std::vector<double> densities;
  for (int p = 0; p < num_parts(); ++p) densities.push_back(part_material(p).density);
  mass_model.SetDensities(densities);
  uniform_lame_ = true;
  for (int p = 1; p < num_parts(); ++p)
    uniform_lame_ = uniform_lame_ && part_material(p).mu() == scene.material.mu() &&
                    part_material(p).lambda() == scene.material.lambda();
  element_mu_.clear();
  element_lambda_.clear();
  if (uniform_lame_) return;
  std::vector<double> part_mu, part_lambda;
  for (int p = 0; p < num_parts(); ++p) {
    part_mu.push_back(part_material(p).mu());
    part_lambda.push_back(part_material(p).lambda());
  }
  element_mu_.resize(part_of_element.size());
  element_lambda_.resize(part_of_element.size());
  for (size_t e = 0; e < part_of_element.size(); ++e) {
    element_mu_[e] = part_mu[part_of_element[e]];
    element_lambda_[e] = part_lambda[part_of_element[e]];
  }
}

LameField SimulatorImpl::lame() const {
  if (uniform_lame_) return LameField::Uniform(scene.material.mu(), scene.material.lambda());
  return LameField::PerElement(element_mu_.data(), element_lambda_.data());
}

VectorXd SimulatorImpl::ExplicitForce(const StepInput& input) const {
  const int n = num_dofs();
  VectorXd f = VectorXd::Zero(n);
  if (scene.gravity) {
    for (int i = 0; i < n / 3; ++i) f.segment<3>(3 * i) = Mass()(3 * i) * (*scene.gravity);
  }
  if (input.external_force.size() > 0) f += input.external_force;
  return f;
}

void SimulatorImpl::ZeroFixed(VectorXd* v) const {
  // A select rather than a branch: the loop vectorises (it runs several
  // times per PD iteration).
  double* data = v->data();
  const char* mask = fixed.data();
  const int n = static_cast<int>(v->size());
#pragma omp simd
  for (int d = 0; d < n; ++d) data[d] = mask[d] ? 0.0 : data[d];
}

HessianAssembler& SimulatorImpl::hessian_assembler() {
  if (!hessian_) hessian_ = std::make_unique<HessianAssembler>(scene.mesh);
  return *hessian_;
}

PdSystem& SimulatorImpl::pd_system() {
  if (!pd_) {
    pd_ = std::make_unique<PdSystem>(fem, fixed, part_of_element, num_parts());
    if (!aux.empty()) pd_->SetAuxiliaryMatrix(aux.PdMatrix());
  }
  // PD-LBFGS preconditions with a softer A (SolverOptions::lbfgs_weight_scale),
  // every part's weight scaled alike.
  const double scale = options.method == Method::kPdLbfgs ? options.lbfgs_weight_scale : 1.0;
  std::vector<double> densities, weights;
  for (int p = 0; p < num_parts(); ++p) {
    const MaterialParameters& m = part_material(p);
    densities.push_back(m.density);
    weights.push_back(scale * elastic.PdWeight(m.mu(), m.lambda()));
  }
  pd_->SetSolveThreads(threads() > 0 ? threads() : omp_get_max_threads());
  pd_->SetCopyMaxBytes(options.pd_factor_copy_max_bytes);
  pd_->Update(h(), densities, weights);
  return *pd_;
}

HessianFactorization& SimulatorImpl::hessian_factorization() {
  const HessianFactorizationKind kind = options.method == Method::kNewtonLdlt
                                            ? HessianFactorizationKind::kSimplicialLdlt
                                            : HessianFactorizationKind::kCholmodSupernodal;
  if (!hessian_factorization_ || hessian_factorization_->kind() != kind)
    hessian_factorization_ = std::make_unique<HessianFactorization>(kind);
  return *hessian_factorization_;
}

void SimulatorImpl::ResetAdjointCostModels() {
  backward_cost_ = AdjointCostModel();
  tangent_cost_.clear();
}

LbfgsPairs& SimulatorImpl::empty_lbfgs_pairs() {
  const int capacity = options.lbfgs_history;
  if (!lbfgs_pairs_ || lbfgs_pairs_->capacity() != capacity || lbfgs_pairs_->dimension() != num_dofs())
    lbfgs_pairs_ = std::make_unique<LbfgsPairs>(capacity, num_dofs());
  lbfgs_pairs_->Clear();
  return *lbfgs_pairs_;
}

namespace {

bool SameMaterial(const MaterialParameters& a, const MaterialParameters& b) {
  return a.youngs_modulus == b.youngs_modulus && a.poissons_ratio == b.poissons_ratio && a.density == b.density;
}

}  // namespace

namespace {

std::string Describe(const MaterialParameters& m) {
  std::ostringstream s;
  s << "E = " << m.youngs_modulus << " Pa, nu = " << m.poissons_ratio << ", rho = " << m.density << " kg/m^3";
  return s.str();
}

}  // namespace

std::string SettingsMismatch(const SimulatorImpl& sim, const MaterialParameters& material,
                             const std::vector<MaterialParameters>& region_materials, const SolverOptions& options) {
  std::ostringstream msg;
  if (!SameMaterial(material, sim.scene.material)) {
    msg << "another material (" << Describe(material) << ") than the simulator's current one ("
        << Describe(sim.scene.material) << ")";
  } else if (region_materials.size() != sim.scene.material_regions.size()) {
    msg << region_materials.size() << " region materials, while the simulator's scene has "
        << sim.scene.material_regions.size() << " regions";
  } else if (options.time_step != sim.h()) {
    msg << "another time step (" << options.time_step << " s) than the simulator's current one (" << sim.h() << " s)";
  } else if (options.method != sim.options.method) {
    msg << "another method (" << ToString(options.method) << ") than the simulator's current one ("
        << ToString(sim.options.method) << ")";
  } else {
    for (size_t r = 0; r < region_materials.size(); ++r)
      if (!SameMaterial(region_materials[r], sim.scene.material_regions[r].material)) {
        msg << "another material of region " << r << " (" << Describe(region_materials[r])
            << ") than the simulator's current one (" << Describe(sim.scene.material_regions[r].material) << ")";
        break;
      }
  }
  return msg.str();
}

VectorXd GravityPerDof(const SimulatorImpl& sim) {
  const int n = sim.num_dofs();
  VectorXd g = VectorXd::Zero(n);
  if (sim.scene.gravity)
    for (int i = 0; i < n / 3; ++i) g.segment<3>(3 * i) = *sim.scene.gravity;
  return g;
}

StepObjective::StepObjective(SimulatorImpl& sim, VectorXd xhat, VectorXd force, bool static_problem)
    : sim_(sim), xhat_(std::move(xhat)), force_(std::move(force)), static_(static_problem) {
  inertia_ = static_problem ? VectorXd::Zero(sim.num_dofs()) : VectorXd(sim.Mass() / (sim.h() * sim.h()));
  if (sim.options.tolerance_reference == ToleranceReference::kInertia && !static_problem) {
    double squares = 0;
    for (int d = 0; d < xhat_.size(); ++d)
      if (!sim.fixed[d]) squares += std::pow(inertia_(d) * xhat_(d) + force_(d), 2);
    reference_residual_ = std::sqrt(squares);
  }
}

VectorXd StepObjective::ElasticGradient(const VectorXd& x, const VectorXd& grad) const {
  VectorXd aux = VectorXd::Zero(x.size());
  sim_.aux.AddEnergyAndGradient(x, sim_.activation, &aux);
  VectorXd out = grad - aux - inertia_.cwiseProduct(x - xhat_) + force_;
  sim_.ZeroFixed(&out);
  return out;
}

namespace {

// Per node (n, N): how much one relative rounding of the deformation
// gradients moves the node's elastic force near positions x,
//   sqrt(sum_s (w_s vol_s |grad N_a(s)| c_s)^2)
// over the samples s of the node's elements, w_s = 2 mu + lambda (the P-wave
// modulus) and c_s = 1 + sqrt(sum_b |x_b|^2 |grad N_b(s)|^2): F = sum_b x_b
// grad N_b^T is formed from absolute positions, so its rounding grows with
// the body's distance from the origin.
VectorXd ElasticRoundingScale(const FemModel& fem, const LameField& lame, const VectorXd& x) {
  const Mesh& mesh = fem.mesh();
  const int k = fem.nodes_per_element(), q = fem.samples_per_element();
  VectorXd squares = VectorXd::Zero(fem.num_nodes());
  std::vector<double> grad_norm(k);
  for (int e = 0; e < fem.num_elements(); ++e) {
    const double w = 2 * lame.mu_of(e) + lame.lambda_of(e);
    for (int j = 0; j < q; ++j) {
      const int s = e * q + j;
      const Eigen::Map<const Eigen::MatrixXd> g(fem.grad(s), k, 3);
      double positions = 0;
      for (int b = 0; b < k; ++b) {
        grad_norm[b] = g.row(b).norm();
        positions += x.segment<3>(3 * mesh.elements(b, e)).squaredNorm() * grad_norm[b] * grad_norm[b];
      }
      const double c = 1 + std::sqrt(positions);
      for (int a = 0; a < k; ++a) {
        const double term = w * fem.sample_volume(s) * grad_norm[a] * c;
        squares(mesh.elements(a, e)) += term * term;
      }
    }
  }
  return squares.cwiseSqrt();
}

}  // namespace

double StepObjective::RoundingFloor() {
  if (rounding_floor_ >= 0) return rounding_floor_;
  const VectorXd elastic = ElasticRoundingScale(sim_.fem, sim_.lame(), xhat_);
  double sum = 0;
  for (int d = 0; d < xhat_.size(); ++d) {
    if (sim_.fixed[d]) continue;
    const double term = inertia_(d) * std::abs(xhat_(d)) + std::abs(force_(d)) + elastic(d / 3);
    sum += term * term;
  }
  rounding_floor_ = std::numeric_limits<double>::epsilon() * std::sqrt(sum);
  return rounding_floor_;
}

bool StepObjective::LastValueAt(const VectorXd& x, double* value) const {
  if (!have_last_ || last_x_.size() != x.size() || last_x_ != x) return false;
  *value = last_value_;
  return true;
}

double StepObjective::Evaluate(const VectorXd& x, VectorXd* grad, bool keep_fixed_rows) {
  have_last_ = false;  // until this evaluation succeeds
  const double e = sim_.elastic.EnergyAndGradient(x, sim_.lame(), grad, sim_.threads());
  const VectorXd dx = x - xhat_;
  double value = e + sim_.aux.AddEnergyAndGradient(x, sim_.activation, grad);
  for (int d = 0; d < x.size(); ++d) {
    if (sim_.fixed[d]) continue;
    value += 0.5 * inertia_(d) * dx(d) * dx(d) - force_(d) * x(d);
  }
  if (grad) {
    grad->array() += inertia_.array() * dx.array() - force_.array();
    if (!keep_fixed_rows) sim_.ZeroFixed(grad);
    CheckFinite(*grad, "grad g");
  }
  if (!std::isfinite(value)) throw SolverError(SolverStatus::kNonFinite, "the step objective g(x) is not finite");
  last_x_ = x;  // same size every time: no allocation after the first
  last_value_ = value;
  have_last_ = true;
  return value;
}

bool StepObjective::StopAtCheckpoint(const VectorXd& x, double grad_norm, double initial_norm) {
  if (!checkpoint_.stop || checkpoint_done_) return false;
  if (grad_norm > checkpoint_.abs_tolerance + checkpoint_.rel_tolerance * initial_norm) return false;
  checkpoint_done_ = true;
  checkpoint_stopped_ = checkpoint_.stop(x);
  return checkpoint_stopped_;
}

bool Converged(const SolverOptions& options, double grad_norm, double initial_norm) {
  // inf <= inf would hold: a non-finite residual never converges.
  return std::isfinite(grad_norm) && std::isfinite(initial_norm) &&
         grad_norm <= options.abs_tolerance + options.rel_tolerance * initial_norm;
}

bool IterationConverged(StepObjective& objective, int it, const VectorXd& x, double grad_norm, StepReport* report) {
  const SolverOptions& options = objective.sim().options;
  report->iterations = it;
  report->final_residual = grad_norm;
  if (options.verbosity >= 2)
    std::fprintf(stderr, "  %s iteration %d |grad g| = %.3e\n", ToString(options.method), it, grad_norm);
  if (!std::isfinite(grad_norm) || !std::isfinite(report->initial_residual)) {
    std::ostringstream msg;
    msg << ToString(options.method) << ": the residual |grad g| = " << grad_norm << " at iteration " << it
        << " (initial " << report->initial_residual
        << ") is not finite: the step's forces or stiffness overflow double precision";
    throw SolverError(SolverStatus::kNonFinite, msg.str());
  }
  if (Converged(options, grad_norm, report->initial_residual)) return true;
  if (objective.StopAtCheckpoint(x, grad_norm, report->initial_residual)) return true;
  if (it >= options.max_iterations) ThrowNotConverged(options, it, grad_norm, report->initial_residual);
  return false;
}

void AppendSolve(const StepReport& later, StepReport* report) {
  report->iterations += later.iterations;
  report->line_search_steps += later.line_search_steps;
  report->energy_restarts += later.energy_restarts;
  report->final_residual = later.final_residual;
  report->rounding_floor_stop = later.rounding_floor_stop;
  report->newton_fallback = report->newton_fallback || later.newton_fallback;
}

VectorXd EndAtRoundingFloor(const VectorXd& x, double grad_norm, StepReport* report) {
  report->rounding_floor_stop = true;
  report->final_residual = grad_norm;
  return x;
}

void ThrowNotConverged(const SolverOptions& options, int iterations, double grad_norm, double initial_norm) {
  std::ostringstream msg;
  msg << ToString(options.method) << ": the step did not converge in " << iterations
      << " iterations (|grad g| = " << grad_norm << ", initial " << initial_norm << ", tolerance "
      << options.abs_tolerance + options.rel_tolerance * initial_norm << ")";
  throw SolverError(SolverStatus::kMaxIterations, msg.str());
}

void CheckFinite(const VectorXd& v, const char* what) {
  if (!v.allFinite()) throw SolverError(SolverStatus::kNonFinite, std::string(what) + " is not finite");
}

}  // namespace diffpd::internal
