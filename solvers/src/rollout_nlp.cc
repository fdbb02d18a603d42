#include "diffpd/solvers/rollout_nlp.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kIpoptInfinity = 1e20;  // beyond Ipopt's default nlp_{lower,upper}_bound_inf (1e19)

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double ClampInfinity(double v) { return std::max(-kIpoptInfinity, std::min(kIpoptInfinity, v)); }

bool SameMaterial(const MaterialParameters& a, const MaterialParameters& b) {
  return a.youngs_modulus == b.youngs_modulus && a.poissons_ratio == b.poissons_ratio && a.density == b.density;
}

// The first `last` steps of `full` (states 0..last).
Rollout Truncated(const Rollout& full, int last) {
  Rollout r;
  r.states.assign(full.states.begin(), full.states.begin() + last + 1);
  r.inputs.assign(full.inputs.begin(), full.inputs.begin() + last);
  r.reports.assign(full.reports.begin(), full.reports.begin() + last);
  r.material = full.material;
  r.region_materials = full.region_materials;
  r.options = full.options;
  return r;
}

double Violation(double value, double lower, double upper) { return std::max({0.0, lower - value, value - upper}); }

}  // namespace

struct RolloutNlp::Cache {
  VectorXd x;
  bool valid = false;  // x holds an evaluated point
  bool ok = false;     // its rollout succeeded
  Rollout rollout;
  bool has_f = false, has_grad = false, has_g = false, has_jac = false;
  double f = 0;
  VectorXd grad, g;
  std::vector<double> jac;  // in the order of row_columns_
};

RolloutNlp::RolloutNlp(Simulator* simulator, RolloutSetup base)
    : sim_(simulator), base_(std::move(base)), cache_(std::make_unique<Cache>()) {
  if (!sim_) throw InvalidInputError("RolloutNlp: the simulator is null");
  const int n = sim_->num_dofs();
  if (base_.inputs.empty()) throw InvalidInputError("RolloutNlp: the base setup has no step (need K >= 1 inputs)");
  if (base_.initial.x.size() != n || base_.initial.v.size() != n) {
    std::ostringstream msg;
    msg << "RolloutNlp: the base initial state has " << base_.initial.x.size() << " positions and "
        << base_.initial.v.size() << " velocities, expected " << n << " each";
    throw InvalidInputError(msg.str());
  }
  base_.material.Validate();
  // Muscles at rest where the base says nothing, so activation blocks can
  // set single entries.
  const Eigen::Index muscles = static_cast<Eigen::Index>(sim_->scene().muscles.size());
  if (muscles > 0)
    for (StepInput& in : base_.inputs)
      if (in.activation.size() == 0) in.activation = VectorXd::Ones(muscles);
}

RolloutNlp::~RolloutNlp() = default;

int RolloutNlp::num_constraints() const { return static_cast<int>(constraints_.size() + linear_.size()); }

const VectorXd& RolloutNlp::starting_point() const {
  return custom_start_.size() == num_variables() && num_variables() > 0 ? custom_start_ : block_start_;
}

int RolloutNlp::AddVariables(std::unique_ptr<ControlVariables> block) {
  if (!block) throw InvalidInputError("RolloutNlp: the variable block is null");
  block->CheckFits(sim_->scene(), static_cast<int>(base_.inputs.size()));
  const int offset = num_variables();
  const int size = block->size();
  lower_.conservativeResize(offset + size);
  upper_.conservativeResize(offset + size);
  block_start_.conservativeResize(offset + size);
  lower_.tail(size) = block->lower();
  upper_.tail(size) = block->upper();
  block_start_.tail(size) = block->initial();
  custom_start_.resize(0);
  block_of_.insert(block_of_.end(), size, static_cast<int>(blocks_.size()));
  blocks_.push_back(Block{std::move(block), offset});
  nnz_jac_ = -1;
  cache_ = std::make_unique<Cache>();
  return offset;
}

void RolloutNlp::AddObjective(std::unique_ptr<TrajectoryFunction> f, double weight) {
  if (!f) throw InvalidInputError("RolloutNlp: the objective term is null");
  if (!std::isfinite(weight)) throw InvalidInputError("RolloutNlp: objective weight " + f->name() + " is not finite");
  objective_.push_back(Term{std::move(f), weight});
  cache_ = std::make_unique<Cache>();
}

void RolloutNlp::AddRegularization(int offset, int count, double weight, double reference) {
  if (offset < 0 || count < 0 || offset + count > num_variables() || !std::isfinite(weight) || !(weight >= 0) ||
      !std::isfinite(reference)) {
    std::ostringstream msg;
    msg << "RolloutNlp: regularization of variables [" << offset << ", " << offset + count << ") with weight " << weight
        << " is invalid: need a range inside [0, " << num_variables() << ") and a finite weight >= 0 and reference";
    throw InvalidInputError(msg.str());
  }
  regularization_.push_back(Regularization{offset, count, weight, reference});
  cache_ = std::make_unique<Cache>();
}

void RolloutNlp::AddConstraint(std::unique_ptr<TrajectoryFunction> g, double lower, double upper) {
  if (!g) throw InvalidInputError("RolloutNlp: the constraint is null");
  if (std::isnan(lower) || std::isnan(upper) || lower > upper) {
    std::ostringstream msg;
    msg << "RolloutNlp: constraint '" << g->name() << "' bounds [" << lower << ", " << upper
        << "] are invalid: need lower <= upper, no NaN";
    throw InvalidInputError(msg.str());
  }
  const int K = static_cast<int>(base_.inputs.size());
  if (g->LastState(K) < 0 || g->LastState(K) > K) {
    std::ostringstream msg;
    msg << "RolloutNlp: constraint '" << g->name() << "' reads state " << g->LastState(K)
        << ", outside the rollout's states [0, " << K << "]";
    throw InvalidInputError(msg.str());
  }
  constraints_.push_back(TrajectoryConstraint{std::move(g), lower, upper});
  nnz_jac_ = -1;
  cache_ = std::make_unique<Cache>();
}

void RolloutNlp::AddLinearConstraint(LinearConstraint c) {
  c.Validate(num_variables());
  linear_.push_back(std::move(c));
  nnz_jac_ = -1;
  cache_ = std::make_unique<Cache>();
}

void RolloutNlp::SetStartingPoint(const VectorXd& x) {
  if (x.size() != num_variables() || !x.allFinite()) {
    std::ostringstream msg;
    msg << "RolloutNlp: the starting point has " << x.size() << " entries, expected " << num_variables()
        << " finite values";
    throw InvalidInputError(msg.str());
  }
  custom_start_ = x;
}

RolloutSetup RolloutNlp::SetupAt(const VectorXd& x) const {
  DIFFPD_CHECK(x.size() == num_variables(), "SetupAt: x has " << x.size() << " entries, expected " << num_variables());
  RolloutSetup setup = base_;
  for (const Block& b : blocks_) b.block->Apply(x.segment(b.offset, b.block->size()), &setup);
  return setup;
}

// ---- evaluation -------------------------------------------------------------

template <typename Fn>
bool RolloutNlp::Guarded(const char* what, Fn&& fn) {
  try {
    return fn();
  } catch (const SolverError& e) {
    last_error_ = std::string(what) + ": solver failed (" + ToString(e.status()) + "): " + e.what();
  } catch (const std::exception& e) {
    last_error_ = std::string(what) + ": " + e.what();
  } catch (...) {
    last_error_ = std::string(what) + ": unknown exception";
  }
  return false;
}

bool RolloutNlp::Update(const Ipopt::Number* x, bool new_x) {
  const Eigen::Map<const VectorXd> xv(x, num_variables());
  // new_x == false promises the last point. The values are compared as
  // well: a caller passing new_x == true for an unchanged point reuses the
  // rollout, and a wrong new_x == false cannot return a stale one.
  if (cache_->valid && cache_->x == xv) return cache_->ok;
  *cache_ = Cache();
  cache_->x = xv;
  cache_->valid = true;
  ++stats_.rollouts;
  cache_->ok = Guarded("rollout", [&] {
    const RolloutSetup setup = SetupAt(cache_->x);
    if (!SameMaterial(setup.material, sim_->scene().material)) sim_->SetMaterial(setup.material);
    const auto start = Clock::now();
    try {
      cache_->rollout = sim_->Simulate(setup.initial, setup.inputs);
    } catch (...) {
      stats_.forward_seconds += Seconds(start);
      throw;
    }
    stats_.forward_seconds += Seconds(start);
    return true;
  });
  if (!cache_->ok) ++stats_.failed_rollouts;
  return cache_->ok;
}

void RolloutNlp::PullBackLoss(const LossGradient& loss, int last, Eigen::Ref<VectorXd> out) {
  const Rollout& full = cache_->rollout;
  if (!SameMaterial(full.material, sim_->scene().material)) sim_->SetMaterial(full.material);
  const auto start = Clock::now();
  RolloutGradient grad;
  try {
    if (last == full.num_steps()) {
      grad = sim_->Backward(full, loss);
    } else {
      LossGradient head = loss;
      head.dx.resize(last + 1);
      head.dv.resize(last + 1);
      grad = sim_->Backward(Truncated(full, last), head);
    }
  } catch (...) {
    stats_.backward_seconds += Seconds(start);
    ++stats_.backward_passes;
    throw;
  }
  stats_.backward_seconds += Seconds(start);
  ++stats_.backward_passes;
  VectorXd part;
  for (const Block& b : blocks_) {
    part.resize(b.block->size());
    b.block->PullBack(cache_->x.segment(b.offset, b.block->size()), grad, part);
    out.segment(b.offset, b.block->size()) += part;
  }
}

bool RolloutNlp::ComputeObjective() {
  if (cache_->has_f) return true;
  return Guarded("objective", [&] {
    double f = 0;
    for (const Term& t : objective_) f += t.weight * t.f->Value(cache_->rollout);
    for (const Regularization& r : regularization_)
      f += 0.5 * r.weight * (cache_->x.segment(r.offset, r.count).array() - r.reference).square().sum();
    if (!std::isfinite(f)) {
      last_error_ = "objective: the value is not finite";
      return false;
    }
    cache_->f = f;
    cache_->has_f = true;
    ConsiderBest();
    return true;
  });
}

bool RolloutNlp::ComputeGradient() {
  if (cache_->has_grad) return true;
  return Guarded("objective gradient", [&] {
    const int K = cache_->rollout.num_steps();
    VectorXd grad = VectorXd::Zero(num_variables());
    if (!objective_.empty()) {
      LossGradient loss(K);
      int last = 0;
      for (const Term& t : objective_) {
        t.f->AddGradient(cache_->rollout, t.weight, &loss);
        last = std::max(last, t.f->LastState(K));
      }
      PullBackLoss(loss, last, grad);
    }
    for (const Regularization& r : regularization_)
      grad.segment(r.offset, r.count).array() +=
          r.weight * (cache_->x.segment(r.offset, r.count).array() - r.reference);
    cache_->grad = std::move(grad);
    cache_->has_grad = true;
    return true;
  });
}

bool RolloutNlp::ComputeConstraints() {
  if (cache_->has_g) return true;
  return Guarded("constraints", [&] {
    VectorXd g(num_constraints());
    for (size_t c = 0; c < constraints_.size(); ++c) g(c) = constraints_[c].g->Value(cache_->rollout);
    for (size_t l = 0; l < linear_.size(); ++l) {
      double value = 0;
      for (size_t j = 0; j < linear_[l].columns.size(); ++j)
        value += linear_[l].coefficients[j] * cache_->x(linear_[l].columns[j]);
      g(constraints_.size() + l) = value;
    }
    cache_->g = std::move(g);
    cache_->has_g = true;
    ConsiderBest();
    return true;
  });
}

bool RolloutNlp::ComputeJacobian() {
  if (cache_->has_jac) return true;
  BuildStructure();
  return Guarded("constraint Jacobian", [&] {
    std::vector<double> values;
    values.reserve(nnz_jac_);
    if (!constraints_.empty()) {
      if (ResolvedJacobianMode() == ConstraintJacobianMode::kForward) {
        if (!ForwardModeAvailable()) {
          last_error_ =
              "constraint Jacobian: forward mode does not cover this problem (muscle activations, contact, "
              "muscles or state forces); use ConstraintJacobianMode::kReverse or kAuto";
          return false;
        }
        JacobianForward(&values);
      } else {
        JacobianReverse(&values);
      }
    }
    for (const LinearConstraint& l : linear_) values.insert(values.end(), l.coefficients.begin(), l.coefficients.end());
    cache_->jac = std::move(values);
    cache_->has_jac = true;
    return true;
  });
}

void RolloutNlp::JacobianReverse(std::vector<double>* values) {
  const int K = cache_->rollout.num_steps();
  VectorXd row(num_variables());
  for (size_t r = 0; r < constraints_.size(); ++r) {
    LossGradient loss(K);
    constraints_[r].g->AddGradient(cache_->rollout, 1.0, &loss);
    row.setZero();
    PullBackLoss(loss, constraints_[r].g->LastState(K), row);
    for (int j : row_columns_[r]) values->push_back(row(j));
  }
}

void RolloutNlp::JacobianForward(std::vector<double>* values) {
  const Rollout& rollout = cache_->rollout;
  const int K = rollout.num_steps();
  const int n = sim_->num_dofs();
  std::vector<InputDirection> directions(num_variables());
  for (const Block& b : blocks_)
    for (int j = 0; j < b.block->size(); ++j) {
      InputDirection& d = directions[b.offset + j];
      d.x0 = VectorXd::Zero(n);
      d.v0 = VectorXd::Zero(n);
      d.external_force.assign(K, VectorXd());
      const bool ok = b.block->AddDirection(cache_->x.segment(b.offset, b.block->size()), j, K, &d);
      DIFFPD_CHECK(ok, "block " << b.block->name() << " lost its forward mode");
    }
  if (!SameMaterial(rollout.material, sim_->scene().material)) sim_->SetMaterial(rollout.material);
  const auto start = Clock::now();
  TangentRollout tangents;
  try {
    tangents = sim_->Tangents(rollout, directions);
  } catch (...) {
    stats_.backward_seconds += Seconds(start);
    ++stats_.backward_passes;
    ++stats_.tangent_passes;
    throw;
  }
  stats_.backward_seconds += Seconds(start);
  ++stats_.backward_passes;
  ++stats_.tangent_passes;
  VectorXd row(num_variables());
  for (size_t r = 0; r < constraints_.size(); ++r) {
    LossGradient loss(K);
    constraints_[r].g->AddGradient(rollout, 1.0, &loss);
    row.setZero();
    for (int k = 0; k <= K; ++k) {
      if (loss.dx[k].size()) row.noalias() += tangents.dx[k].transpose() * loss.dx[k];
      if (loss.dv[k].size()) row.noalias() += tangents.dv[k].transpose() * loss.dv[k];
    }
    for (int j : row_columns_[r]) values->push_back(row(j));
  }
}

bool RolloutNlp::ForwardModeAvailable() const {
  const Scene& scene = sim_->scene();
  if (!scene.muscles.empty() || !scene.frictional_contacts.empty() || !scene.penalty_contacts.empty() ||
      scene.hydrodynamics || scene.linear_damping)
    return false;
  const int K = static_cast<int>(base_.inputs.size());
  const int n = sim_->num_dofs();
  for (const Block& b : blocks_) {
    if (b.block->size() == 0) continue;
    InputDirection probe;
    probe.x0 = VectorXd::Zero(n);
    probe.v0 = VectorXd::Zero(n);
    probe.external_force.assign(K, VectorXd());
    if (!b.block->AddDirection(b.block->initial(), 0, K, &probe)) return false;
  }
  return true;
}

ConstraintJacobianMode RolloutNlp::ResolvedJacobianMode() const {
  if (jacobian_mode_ != ConstraintJacobianMode::kAuto) return jacobian_mode_;
  return ForwardModeAvailable() && num_variables() < static_cast<int>(constraints_.size())
             ? ConstraintJacobianMode::kForward
             : ConstraintJacobianMode::kReverse;
}

const char* ToString(ConstraintJacobianMode mode) {
  switch (mode) {
    case ConstraintJacobianMode::kAuto:
      return "auto";
    case ConstraintJacobianMode::kReverse:
      return "reverse";
    case ConstraintJacobianMode::kForward:
      return "forward";
  }
  return "unknown";
}

void RolloutNlp::BuildStructure() {
  if (nnz_jac_ >= 0) return;
  const int K = static_cast<int>(base_.inputs.size());
  row_columns_.clear();
  std::vector<int> first(num_variables());
  for (int j = 0; j < num_variables(); ++j) {
    const Block& b = blocks_[block_of_[j]];
    first[j] = b.block->FirstAffectedState(j - b.offset);
  }
  for (const TrajectoryConstraint& c : constraints_) {
    const int last = c.g->LastState(K);
    std::vector<int> cols;
    for (int j = 0; j < num_variables(); ++j)
      if (first[j] <= last) cols.push_back(j);
    row_columns_.push_back(std::move(cols));
  }
  for (const LinearConstraint& l : linear_) row_columns_.push_back(l.columns);
  nnz_jac_ = 0;
  for (const auto& cols : row_columns_) nnz_jac_ += static_cast<int>(cols.size());
}

// ---- public evaluation ------------------------------------------------------

bool RolloutNlp::Objective(const VectorXd& x, double* f) {
  if (x.size() != num_variables()) return false;
  if (!Update(x.data(), true) || !ComputeObjective()) return false;
  *f = cache_->f;
  return true;
}

bool RolloutNlp::ObjectiveGradient(const VectorXd& x, VectorXd* grad) {
  if (x.size() != num_variables()) return false;
  if (!Update(x.data(), true) || !ComputeGradient()) return false;
  *grad = cache_->grad;
  return true;
}

bool RolloutNlp::Constraints(const VectorXd& x, VectorXd* g) {
  if (x.size() != num_variables()) return false;
  if (!Update(x.data(), true) || !ComputeConstraints()) return false;
  *g = cache_->g;
  return true;
}

bool RolloutNlp::ConstraintJacobian(const VectorXd& x, MatrixXd* jacobian) {
  if (x.size() != num_variables()) return false;
  if (!Update(x.data(), true) || !ComputeJacobian()) return false;
  jacobian->setZero(num_constraints(), num_variables());
  size_t k = 0;
  for (size_t r = 0; r < row_columns_.size(); ++r)
    for (int j : row_columns_[r]) (*jacobian)(r, j) = cache_->jac[k++];
  return true;
}

const Rollout* RolloutNlp::RolloutAt(const VectorXd& x) {
  if (x.size() != num_variables()) return nullptr;
  return Update(x.data(), true) ? &cache_->rollout : nullptr;
}

void RolloutNlp::ResetBestFeasible(double tolerance) {
  best_x_.resize(0);
  best_f_ = 0;
  best_tolerance_ = tolerance;
}

void RolloutNlp::ConsiderBest() {
  if (!cache_->ok || !cache_->has_f) return;
  if (!cache_->has_g) {
    if (num_constraints() > 0) return;
    cache_->g.resize(0);
    cache_->has_g = true;
  }
  if (has_best_feasible() && cache_->f >= best_f_) return;
  double v = 0;
  for (size_t c = 0; c < constraints_.size(); ++c)
    v = std::max(v, Violation(cache_->g(c), constraints_[c].lower, constraints_[c].upper));
  for (size_t l = 0; l < linear_.size(); ++l)
    v = std::max(v, Violation(cache_->g(constraints_.size() + l), linear_[l].lower, linear_[l].upper));
  for (int j = 0; j < num_variables(); ++j) v = std::max(v, Violation(cache_->x(j), lower_(j), upper_(j)));
  if (v > best_tolerance_) return;
  best_x_ = cache_->x;
  best_f_ = cache_->f;
}

double RolloutNlp::ConstraintViolation(const VectorXd& x) {
  VectorXd g;
  if (!Constraints(x, &g)) return std::numeric_limits<double>::infinity();
  double v = 0;
  for (size_t c = 0; c < constraints_.size(); ++c)
    v = std::max(v, Violation(g(c), constraints_[c].lower, constraints_[c].upper));
  for (size_t l = 0; l < linear_.size(); ++l)
    v = std::max(v, Violation(g(constraints_.size() + l), linear_[l].lower, linear_[l].upper));
  for (int j = 0; j < num_variables(); ++j) v = std::max(v, Violation(x(j), lower_(j), upper_(j)));
  return v;
}

// ---- Ipopt::TNLP --------------------------------------------------------------

bool RolloutNlp::get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                              IndexStyleEnum& index_style) {
  BuildStructure();
  n = num_variables();
  m = num_constraints();
  nnz_jac_g = nnz_jac_;
  nnz_h_lag = 0;  // limited-memory Hessian
  index_style = C_STYLE;
  return true;
}

bool RolloutNlp::get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m,
                                 Ipopt::Number* g_l, Ipopt::Number* g_u) {
  if (n != num_variables() || m != num_constraints()) return false;
  for (int j = 0; j < n; ++j) {
    x_l[j] = ClampInfinity(lower_(j));
    x_u[j] = ClampInfinity(upper_(j));
  }
  for (size_t c = 0; c < constraints_.size(); ++c) {
    g_l[c] = ClampInfinity(constraints_[c].lower);
    g_u[c] = ClampInfinity(constraints_[c].upper);
  }
  for (size_t l = 0; l < linear_.size(); ++l) {
    g_l[constraints_.size() + l] = ClampInfinity(linear_[l].lower);
    g_u[constraints_.size() + l] = ClampInfinity(linear_[l].upper);
  }
  return true;
}

bool RolloutNlp::get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number* z_L,
                                    Ipopt::Number* z_U, Ipopt::Index m, bool init_lambda, Ipopt::Number* lambda) {
  if (n != num_variables() || init_z || init_lambda) return false;  // no multipliers to warm-start from
  if (init_x) Eigen::Map<VectorXd>(x, n) = starting_point();
  return true;
}

bool RolloutNlp::get_constraints_linearity(Ipopt::Index m, LinearityType* const_types) {
  if (m != num_constraints()) return false;
  for (size_t c = 0; c < constraints_.size(); ++c) const_types[c] = NON_LINEAR;
  for (size_t l = 0; l < linear_.size(); ++l) const_types[constraints_.size() + l] = LINEAR;
  return true;
}

bool RolloutNlp::eval_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number& obj_value) {
  if (n != num_variables() || !Update(x, new_x) || !ComputeObjective()) return false;
  obj_value = cache_->f;
  return true;
}

bool RolloutNlp::eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number* grad_f) {
  if (n != num_variables() || !Update(x, new_x) || !ComputeGradient()) return false;
  Eigen::Map<VectorXd>(grad_f, n) = cache_->grad;
  return true;
}

bool RolloutNlp::eval_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Number* g) {
  if (n != num_variables() || m != num_constraints() || !Update(x, new_x) || !ComputeConstraints()) return false;
  Eigen::Map<VectorXd>(g, m) = cache_->g;
  return true;
}

bool RolloutNlp::eval_jac_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Index nele_jac,
                            Ipopt::Index* iRow, Ipopt::Index* jCol, Ipopt::Number* values) {
  BuildStructure();
  if (n != num_variables() || m != num_constraints() || nele_jac != nnz_jac_) return false;
  if (values == nullptr) {  // structure call: x may be null
    if (!iRow || !jCol) return false;
    int k = 0;
    for (size_t r = 0; r < row_columns_.size(); ++r)
      for (int j : row_columns_[r]) {
        iRow[k] = static_cast<Ipopt::Index>(r);
        jCol[k] = j;
        ++k;
      }
    return true;
  }
  if (!x || !Update(x, new_x) || !ComputeJacobian()) return false;
  std::copy(cache_->jac.begin(), cache_->jac.end(), values);
  return true;
}

bool RolloutNlp::intermediate_callback(Ipopt::AlgorithmMode mode, Ipopt::Index iter, Ipopt::Number obj_value,
                                       Ipopt::Number inf_pr, Ipopt::Number inf_du, Ipopt::Number mu,
                                       Ipopt::Number d_norm, Ipopt::Number regularization_size, Ipopt::Number alpha_du,
                                       Ipopt::Number alpha_pr, Ipopt::Index ls_trials, const Ipopt::IpoptData* ip_data,
                                       Ipopt::IpoptCalculatedQuantities* ip_cq) {
  iterations_.push_back(IterationRecord{iter, obj_value, inf_pr, mode == Ipopt::RestorationPhaseMode});
  return true;
}

void RolloutNlp::finalize_solution(Ipopt::SolverReturn status, Ipopt::Index n, const Ipopt::Number* x,
                                   const Ipopt::Number* z_L, const Ipopt::Number* z_U, Ipopt::Index m,
                                   const Ipopt::Number* g, const Ipopt::Number* lambda, Ipopt::Number obj_value,
                                   const Ipopt::IpoptData* ip_data, Ipopt::IpoptCalculatedQuantities* ip_cq) {
  has_solution_ = true;
  solution_status_ = status;
  solution_ = x ? VectorXd(Eigen::Map<const VectorXd>(x, n)) : VectorXd();
  solution_objective_ = obj_value;
}

}  // namespace diffpd::solvers
