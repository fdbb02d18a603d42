#include "diffpd/solvers/ipopt/rollout_nlp.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

constexpr double kIpoptInfinity = 1e20;  // beyond Ipopt's default nlp_{lower,upper}_bound_inf (1e19)

double ClampInfinity(double v) { return std::max(-kIpoptInfinity, std::min(kIpoptInfinity, v)); }

double Excess(double value, double lower, double upper) { return std::max({0.0, lower - value, value - upper}); }

}  // namespace

RolloutNlp::RolloutNlp(std::unique_ptr<RolloutFunction> function) : function_(std::move(function)) {
  if (!function_) throw InvalidInputError("RolloutNlp: the rollout function is null");
}

RolloutNlp::~RolloutNlp() = default;

VectorXd RolloutNlp::starting_point() const {
  return custom_start_.size() == num_variables() && num_variables() > 0 ? custom_start_
                                                                        : function_->initial_parameters();
}

int RolloutNlp::AddVariables(std::unique_ptr<ParameterBlock> block) {
  const int offset = function_->AddBlock(std::move(block));
  custom_start_.resize(0);
  nnz_jac_ = -1;
  record_ = PointRecord();
  return offset;
}

void RolloutNlp::CheckRows(const std::vector<int>& rows, const char* what) const {
  for (int r : rows)
    if (r < 0 || r >= function_->num_rows()) {
      std::ostringstream msg;
      msg << "RolloutNlp: " << what << " row " << r << " is out of range [0, " << function_->num_rows() << ")";
      throw InvalidInputError(msg.str());
    }
}

void RolloutNlp::AddObjective(std::unique_ptr<TrajectoryFunctional> f, double weight) {
  if (!f) throw InvalidInputError("RolloutNlp: the objective term is null");
  if (!std::isfinite(weight)) throw InvalidInputError("RolloutNlp: objective weight " + f->name() + " is not finite");
  AddObjectiveRows(function_->RowsOf(function_->AddFunctional(std::move(f))), weight);
}

void RolloutNlp::AddObjectiveRows(const std::vector<int>& rows, double weight) {
  CheckRows(rows, "objective");
  if (!std::isfinite(weight)) throw InvalidInputError("RolloutNlp: an objective weight is not finite");
  const Eigen::Index old = objective_weights_.size();
  objective_weights_.conservativeResize(function_->num_rows());
  objective_weights_.tail(objective_weights_.size() - old).setZero();
  for (int r : rows) objective_weights_(r) += weight;
  record_ = PointRecord();
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
  record_ = PointRecord();
}

void RolloutNlp::AddConstraint(std::unique_ptr<TrajectoryFunctional> g, double lower, double upper) {
  if (!g) throw InvalidInputError("RolloutNlp: the constraint is null");
  if (std::isnan(lower) || std::isnan(upper) || lower > upper) {
    std::ostringstream msg;
    msg << "RolloutNlp: constraint '" << g->name() << "' bounds [" << lower << ", " << upper
        << "] are invalid: need lower <= upper, no NaN";
    throw InvalidInputError(msg.str());
  }
  AddConstraintRows(function_->RowsOf(function_->AddFunctional(std::move(g))), lower, upper);
}

void RolloutNlp::AddConstraintRows(const std::vector<int>& rows, double lower, double upper) {
  CheckRows(rows, "constraint");
  if (std::isnan(lower) || std::isnan(upper) || lower > upper) {
    std::ostringstream msg;
    msg << "RolloutNlp: constraint bounds [" << lower << ", " << upper << "] are invalid: need lower <= upper, no NaN";
    throw InvalidInputError(msg.str());
  }
  for (int r : rows) {
    constraint_rows_.push_back(r);
    constraint_lower_.push_back(lower);
    constraint_upper_.push_back(upper);
  }
  nnz_jac_ = -1;
  record_ = PointRecord();
}

void RolloutNlp::AddLinearConstraint(LinearConstraint c) {
  c.Validate(num_variables());
  linear_.push_back(std::move(c));
  nnz_jac_ = -1;
  record_ = PointRecord();
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

DerivativeMode RolloutNlp::ResolvedJacobianMode() const {
  return function_->ResolvedMode(static_cast<int>(constraint_rows_.size()));
}

void RolloutNlp::BuildStructure() {
  if (nnz_jac_ >= 0) return;
  row_columns_.clear();
  std::vector<int> first(num_variables());
  for (int j = 0; j < num_variables(); ++j) first[j] = function_->FirstAffectedState(j);
  for (int r : constraint_rows_) {
    const int last = function_->LastState(r);
    std::vector<int> cols;
    for (int j = 0; j < num_variables(); ++j)
      if (first[j] <= last) cols.push_back(j);
    row_columns_.push_back(std::move(cols));
  }
  for (const LinearConstraint& l : linear_) row_columns_.push_back(l.columns);
  nnz_jac_ = 0;
  for (const auto& cols : row_columns_) nnz_jac_ += static_cast<int>(cols.size());
}

// ---- evaluation -------------------------------------------------------------

RolloutNlp::PointRecord& RolloutNlp::Record(const Eigen::Ref<const VectorXd>& x) {
  if (!(record_.x.size() == x.size() && record_.x == x)) {
    record_ = PointRecord();
    record_.x = x;
  }
  return record_;
}

bool RolloutNlp::Objective(const VectorXd& x, double* f) {
  if (x.size() != num_variables()) return false;
  VectorXd values;
  if (!function_->Evaluate(x, function_->AllRows(), &values, nullptr)) return false;
  VectorXd weights = VectorXd::Zero(function_->num_rows());
  weights.head(objective_weights_.size()) = objective_weights_;
  double value = weights.dot(values);
  for (const Regularization& r : regularization_)
    value += 0.5 * r.weight * (x.segment(r.offset, r.count).array() - r.reference).square().sum();
  *f = value;
  PointRecord& record = Record(x);
  record.has_f = true;
  record.f = value;
  ConsiderBest(record);
  return true;
}

bool RolloutNlp::ObjectiveGradient(const VectorXd& x, VectorXd* grad) {
  if (x.size() != num_variables()) return false;
  VectorXd weights = VectorXd::Zero(function_->num_rows());
  weights.head(objective_weights_.size()) = objective_weights_;
  if (!function_->Gradient(x, weights, grad)) return false;
  for (const Regularization& r : regularization_)
    grad->segment(r.offset, r.count).array() += r.weight * (x.segment(r.offset, r.count).array() - r.reference);
  return true;
}

bool RolloutNlp::Constraints(const VectorXd& x, VectorXd* g) {
  if (x.size() != num_variables()) return false;
  VectorXd values;
  if (!function_->Evaluate(x, constraint_rows_, &values, nullptr)) return false;
  g->resize(num_constraints());
  g->head(constraint_rows_.size()) = values;
  for (size_t l = 0; l < linear_.size(); ++l) {
    double value = 0;
    for (size_t j = 0; j < linear_[l].columns.size(); ++j)
      value += linear_[l].coefficients[j] * x(linear_[l].columns[j]);
    (*g)(constraint_rows_.size() + l) = value;
  }
  PointRecord& record = Record(x);
  record.has_g = true;
  record.g = *g;
  ConsiderBest(record);
  return true;
}

bool RolloutNlp::ConstraintJacobian(const VectorXd& x, MatrixXd* jacobian) {
  if (x.size() != num_variables()) return false;
  MatrixXd rows;
  if (!constraint_rows_.empty() && !function_->Evaluate(x, constraint_rows_, nullptr, &rows)) return false;
  jacobian->setZero(num_constraints(), num_variables());
  BuildStructure();
  // Structural zeros stay zero: the declared columns only.
  for (size_t r = 0; r < constraint_rows_.size(); ++r)
    for (int j : row_columns_[r]) (*jacobian)(r, j) = rows(r, j);
  for (size_t l = 0; l < linear_.size(); ++l)
    for (size_t j = 0; j < linear_[l].columns.size(); ++j)
      (*jacobian)(constraint_rows_.size() + l, linear_[l].columns[j]) = linear_[l].coefficients[j];
  return true;
}

void RolloutNlp::ResetBestFeasible(double tolerance) {
  best_x_.resize(0);
  best_f_ = 0;
  best_tolerance_ = tolerance;
}

double RolloutNlp::Violation(const VectorXd& x, const VectorXd& g) const {
  const VectorXd lower = function_->lower_bounds(), upper = function_->upper_bounds();
  double v = 0;
  for (size_t c = 0; c < constraint_rows_.size(); ++c)
    v = std::max(v, Excess(g(c), constraint_lower_[c], constraint_upper_[c]));
  for (size_t l = 0; l < linear_.size(); ++l)
    v = std::max(v, Excess(g(constraint_rows_.size() + l), linear_[l].lower, linear_[l].upper));
  for (int j = 0; j < num_variables(); ++j) v = std::max(v, Excess(x(j), lower(j), upper(j)));
  return v;
}

void RolloutNlp::ConsiderBest(const PointRecord& record) {
  if (!record.has_f || (!record.has_g && num_constraints() > 0)) return;
  if (has_best_feasible() && record.f >= best_f_) return;
  if (Violation(record.x, record.has_g ? record.g : VectorXd()) > best_tolerance_) return;
  best_x_ = record.x;
  best_f_ = record.f;
}

double RolloutNlp::ConstraintViolation(const VectorXd& x) {
  VectorXd g;
  if (!Constraints(x, &g)) return std::numeric_limits<double>::infinity();
  return Violation(x, g);
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
  const VectorXd lower = function_->lower_bounds(), upper = function_->upper_bounds();
  for (int j = 0; j < n; ++j) {
    x_l[j] = ClampInfinity(lower(j));
    x_u[j] = ClampInfinity(upper(j));
  }
  for (size_t c = 0; c < constraint_rows_.size(); ++c) {
    g_l[c] = ClampInfinity(constraint_lower_[c]);
    g_u[c] = ClampInfinity(constraint_upper_[c]);
  }
  for (size_t l = 0; l < linear_.size(); ++l) {
    g_l[constraint_rows_.size() + l] = ClampInfinity(linear_[l].lower);
    g_u[constraint_rows_.size() + l] = ClampInfinity(linear_[l].upper);
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
  for (size_t c = 0; c < constraint_rows_.size(); ++c) const_types[c] = NON_LINEAR;
  for (size_t l = 0; l < linear_.size(); ++l) const_types[constraint_rows_.size() + l] = LINEAR;
  return true;
}

bool RolloutNlp::eval_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number& obj_value) {
  if (n != num_variables()) return false;
  return Objective(Eigen::Map<const VectorXd>(x, n), &obj_value);
}

bool RolloutNlp::eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number* grad_f) {
  if (n != num_variables()) return false;
  VectorXd grad;
  if (!ObjectiveGradient(Eigen::Map<const VectorXd>(x, n), &grad)) return false;
  Eigen::Map<VectorXd>(grad_f, n) = grad;
  return true;
}

bool RolloutNlp::eval_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Number* g) {
  if (n != num_variables() || m != num_constraints()) return false;
  VectorXd values;
  if (!Constraints(Eigen::Map<const VectorXd>(x, n), &values)) return false;
  Eigen::Map<VectorXd>(g, m) = values;
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
  MatrixXd rows;
  if (!x || (!constraint_rows_.empty() &&
             !function_->Evaluate(Eigen::Map<const VectorXd>(x, n), constraint_rows_, nullptr, &rows)))
    return false;
  int k = 0;
  for (size_t r = 0; r < constraint_rows_.size(); ++r)
    for (int j : row_columns_[r]) values[k++] = rows(r, j);
  for (const LinearConstraint& l : linear_)
    for (double c : l.coefficients) values[k++] = c;
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
