// Independent rollouts that share one parameter vector p (N values): the
// terms of a calibration against several recordings, of a multi-start, of a
// controller trained over several initial states,
//
//   v(p) = [v_0(p); v_1(p); ...; v_{T-1}(p)],     L(p) = sum_t L_t(p),
//
// term t a RolloutFunction (rollout_function.h) over the same parameters and
// v_t the term's chosen rows; L_t = 1/2 |v_t|^2 (TermObjective::kLeastSquares)
// or the sum of v_t's entries (kSum). Terms are combined in term order.
//
// RolloutSet is what the optimiser adapters evaluate (a Ceres cost function
// over v, a first-order function of L: ceres/rollout_set_cost_function.h,
// ceres/rollout_set_loss_function.h).
// LocalRolloutSet evaluates the terms one after another in this process;
// DistributedRolloutSet (diffpd/solvers/mpi/distributed_rollout_set.h)
// spreads them over MPI ranks. Both compute every term with
// EvaluateRolloutTerm / RolloutTermGradient and combine the terms in the
// same order, so their results agree bit for bit when the terms'
// simulations are deterministic (fixed thread counts and a fixed
// SolverOptions::adjoint_solver: kAuto's choices depend on what each
// simulator solved before).
//
// Failures: Evaluate and Gradient never throw; false, with the reason in
// last_error() ("term 2: rollout failed (...)").
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "diffpd/solvers/core/rollout_function.h"

namespace diffpd::solvers {

// What a term contributes to the scalar L.
enum class TermObjective {
  kLeastSquares,  // L_t = 1/2 sum_r v_r^2 (residual rows)
  kSum,           // L_t = sum_r v_r (e.g. one loss row)
};

// One term: its rollout function (owned) and the rows it contributes.
struct RolloutTerm {
  std::unique_ptr<RolloutFunction> function;
  std::vector<int> rows;
};

// Throws InvalidInputError for a term without function or rows, or with a
// row out of range ("rollout term: row 9 is out of range [0, 6)").
void CheckRolloutTerm(const RolloutTerm& term);

// v_t (rows) and, if jacobian is not nullptr, dv_t/dp (rows x N). False on
// failure, the reason in *error (never throws).
bool EvaluateRolloutTerm(RolloutTerm* term, const Eigen::Ref<const VectorXd>& p, VectorXd* values, MatrixXd* jacobian,
                         std::string* error);
// L_t and dL_t/dp (N) by one adjoint pass. False on failure, the reason in
// *error (never throws).
bool RolloutTermGradient(RolloutTerm* term, TermObjective objective, const Eigen::Ref<const VectorXd>& p,
                         VectorXd* gradient, double* value, std::string* error);

class RolloutSet {
 public:
  virtual ~RolloutSet() = default;

  virtual int num_terms() const = 0;
  virtual int num_parameters() const = 0;
  // Rows of term t; all rows (their sum).
  virtual int term_rows(int t) const = 0;
  virtual int num_rows() const = 0;
  virtual TermObjective objective() const = 0;
  // Term 0's starting values and bounds (ParameterBlock), N each.
  virtual VectorXd initial_parameters() const = 0;
  virtual VectorXd lower_bounds() const = 0;
  virtual VectorXd upper_bounds() const = 0;

  // v(p) (num_rows()) and, if jacobian is not nullptr, dv/dp (num_rows() x N).
  virtual bool Evaluate(const Eigen::Ref<const VectorXd>& p, VectorXd* values, MatrixXd* jacobian) = 0;
  // dL/dp (N) and, if value is not nullptr, L(p).
  virtual bool Gradient(const Eigen::Ref<const VectorXd>& p, VectorXd* gradient, double* value) = 0;
  // L(p) from Evaluate's rows (no derivative).
  bool Value(const Eigen::Ref<const VectorXd>& p, double* value);
  virtual const std::string& last_error() const = 0;
  // The statistics of the terms evaluated in this process, summed.
  virtual RolloutStatistics statistics() const = 0;
};

// The terms evaluated one after another in this process.
class LocalRolloutSet : public RolloutSet {
 public:
  // Throws InvalidInputError for no term, an invalid term (CheckRolloutTerm)
  // or terms with different parameter counts ("LocalRolloutSet: term 1 has
  // 3 parameters, term 0 has 2").
  LocalRolloutSet(std::vector<RolloutTerm> terms, TermObjective objective);

  int num_terms() const override { return static_cast<int>(terms_.size()); }
  int num_parameters() const override { return terms_[0].function->num_parameters(); }
  int term_rows(int t) const override { return static_cast<int>(terms_.at(t).rows.size()); }
  int num_rows() const override { return num_rows_; }
  TermObjective objective() const override { return objective_; }
  VectorXd initial_parameters() const override { return terms_[0].function->initial_parameters(); }
  VectorXd lower_bounds() const override { return terms_[0].function->lower_bounds(); }
  VectorXd upper_bounds() const override { return terms_[0].function->upper_bounds(); }
  bool Evaluate(const Eigen::Ref<const VectorXd>& p, VectorXd* values, MatrixXd* jacobian) override;
  bool Gradient(const Eigen::Ref<const VectorXd>& p, VectorXd* gradient, double* value) override;
  const std::string& last_error() const override { return last_error_; }
  RolloutStatistics statistics() const override;

  RolloutTerm& term(int t) { return terms_.at(t); }

 private:
  std::vector<RolloutTerm> terms_;
  TermObjective objective_;
  int num_rows_ = 0;
  std::string last_error_;
};

// The sum of two runs' statistics (counts and seconds; the later last_error).
RolloutStatistics operator+(const RolloutStatistics& a, const RolloutStatistics& b);

}  // namespace diffpd::solvers
