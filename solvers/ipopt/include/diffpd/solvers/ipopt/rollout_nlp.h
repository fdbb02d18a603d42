// An Ipopt nonlinear program over a differentiable rollout (Ipopt 3.11 TNLP):
//
//   min_x   sum_t w_t sum(r_t(x)) + sum_r (w_r / 2) |x_r - ref_r|^2
//   s.t.    lower_c <= r_c(x) <= upper_c           (trajectory constraints)
//           lower_l <= a_l . x <= upper_l           (linear constraints)
//           x_lower <= x <= x_upper                 (variable bounds)
//
// x is the parameter vector of a RolloutFunction (rollout_function.h): its
// parameter blocks are the variables (bounds and starting values from the
// blocks), its functionals' rows the objective terms r_t and the
// constraints r_c. Constraint order: trajectory constraint rows in the order
// added, then linear constraints in the order added.
//
// Derivatives come from the rollout function, all exact to the simulator's
// tolerances: the objective gradient is one adjoint pass per point; the
// constraint Jacobian is the function's Jacobian of the constraint rows
// (forward or reverse mode, SetJacobianMode; kAuto chooses by shape). The
// Hessian: none; run Ipopt with hessian_approximation = limited-memory
// (ipopt_solve.h sets it).
//
// Jacobian sparsity is declared honestly: a constraint row whose last state
// is k has an entry for variable j iff the variable can influence some state
// <= k (RolloutFunction::FirstAffectedState(j) <= k), so per-step controls
// after a path constraint's step are structurally zero; linear rows list
// their own columns. Everything else in a row is dense.
//
// One rollout per evaluation point: the rollout function caches it (keyed on
// the values of x, which honours Ipopt's new_x flag and never serves a stale
// rollout). A failed rollout or derivative makes eval_* return false, so
// Ipopt cuts its step; the message is kept in last_error(). Nothing throws
// through Ipopt.
//
// Create with `new` and hold in an Ipopt::SmartPtr when handing it to Ipopt
// (Ipopt reference-counts it); tests may also call the TNLP methods directly
// on a stack object.
#pragma once

#include <IpTNLP.hpp>

#include <memory>
#include <string>
#include <vector>

#include "diffpd/solvers/core/parameter_block.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "diffpd/solvers/core/trajectory_functional.h"
#include "diffpd/solvers/ipopt/linear_constraint.h"

namespace diffpd::solvers {

// One Ipopt iteration as reported to intermediate_callback.
struct IterationRecord {
  int iteration = 0;
  double objective = 0;
  double primal_infeasibility = 0;  // Ipopt's inf_pr (max constraint violation, scaled problem)
  bool restoration = false;         // Ipopt was in its restoration phase
};

class RolloutNlp : public Ipopt::TNLP {
 public:
  // Takes ownership of `function`; its blocks and functionals so far may be
  // used through the *Rows methods. Throws InvalidInputError if it is null.
  explicit RolloutNlp(std::unique_ptr<RolloutFunction> function);
  ~RolloutNlp() override;

  RolloutFunction& function() { return *function_; }
  const RolloutFunction& function() const { return *function_; }

  // Appends a block of variables (RolloutFunction::AddBlock); returns the
  // index of its first variable.
  int AddVariables(std::unique_ptr<ParameterBlock> block);
  // Adds weight * (sum of f's values) to the objective (f is added to the
  // function). Throws InvalidInputError for a null f or a non-finite weight.
  void AddObjective(std::unique_ptr<TrajectoryFunctional> f, double weight = 1.0);
  void AddObjectiveRows(const std::vector<int>& rows, double weight = 1.0);
  // Adds (weight / 2) |x[offset .. offset+count) - reference|^2.
  void AddRegularization(int offset, int count, double weight, double reference = 0.0);
  // lower <= every value of g <= upper (lower == upper: equality;
  // +-infinity: one-sided); g is added to the function.
  void AddConstraint(std::unique_ptr<TrajectoryFunctional> g, double lower, double upper);
  void AddConstraintRows(const std::vector<int>& rows, double lower, double upper);
  void AddLinearConstraint(LinearConstraint c);
  // Replaces the starting point (default: the blocks' initial values, which
  // it also becomes again when a block is added afterwards). Throws
  // InvalidInputError on a size mismatch or a non-finite entry.
  void SetStartingPoint(const VectorXd& x);

  // The rollout function's derivative mode for the constraint Jacobian.
  void SetJacobianMode(DerivativeMode mode) { function_->SetDerivativeMode(mode); }
  bool ForwardModeAvailable() const { return function_->ForwardModeAvailable(); }
  // kForward or kReverse: what the constraint Jacobian is computed by.
  DerivativeMode ResolvedJacobianMode() const;

  int num_variables() const { return function_->num_parameters(); }
  int num_constraints() const { return static_cast<int>(constraint_rows_.size() + linear_.size()); }
  VectorXd starting_point() const;
  const ParameterBlock& block(int b) const { return function_->block(b); }
  int num_blocks() const { return function_->num_blocks(); }

  // The same evaluations as the TNLP methods, for callers outside Ipopt.
  // Each returns false (and sets last_error()) on a failed rollout/derivative.
  bool Objective(const VectorXd& x, double* f);
  bool ObjectiveGradient(const VectorXd& x, VectorXd* grad);
  bool Constraints(const VectorXd& x, VectorXd* g);
  // Dense m x n Jacobian (structural zeros included as 0).
  bool ConstraintJacobian(const VectorXd& x, MatrixXd* jacobian);
  // The rollout at x (simulated if not cached); nullptr on failure.
  const Rollout* RolloutAt(const VectorXd& x) { return function_->RolloutAt(x); }
  // Largest violation of the constraint and variable bounds at x (>= 0);
  // +infinity if the rollout fails.
  double ConstraintViolation(const VectorXd& x);

  // The feasible point with the lowest objective among the evaluation
  // points where both f and g were evaluated (Ipopt evaluates both at every
  // trial point): constraints and bounds met within `tolerance`. Cleared by
  // ResetBestFeasible (SolveWithIpopt does so before solving).
  void ResetBestFeasible(double tolerance = 1e-6);
  bool has_best_feasible() const { return best_x_.size() > 0; }
  const VectorXd& best_feasible_x() const { return best_x_; }
  double best_feasible_objective() const { return best_f_; }

  // The rollout function's counters and timings (rollouts, passes, seconds).
  const RolloutStatistics& statistics() const { return function_->statistics(); }
  const std::vector<IterationRecord>& iterations() const { return iterations_; }
  const std::string& last_error() const { return function_->statistics().last_error; }
  // What finalize_solution reported (valid once Ipopt has finished).
  bool has_solution() const { return has_solution_; }
  Ipopt::SolverReturn solution_status() const { return solution_status_; }
  const VectorXd& solution() const { return solution_; }
  double solution_objective() const { return solution_objective_; }

  // ---- Ipopt::TNLP ----
  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override;
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m, Ipopt::Number* g_l,
                       Ipopt::Number* g_u) override;
  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number* z_L,
                          Ipopt::Number* z_U, Ipopt::Index m, bool init_lambda, Ipopt::Number* lambda) override;
  bool get_constraints_linearity(Ipopt::Index m, LinearityType* const_types) override;
  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number& obj_value) override;
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number* grad_f) override;
  bool eval_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Number* g) override;
  bool eval_jac_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Index nele_jac,
                  Ipopt::Index* iRow, Ipopt::Index* jCol, Ipopt::Number* values) override;
  bool intermediate_callback(Ipopt::AlgorithmMode mode, Ipopt::Index iter, Ipopt::Number obj_value,
                             Ipopt::Number inf_pr, Ipopt::Number inf_du, Ipopt::Number mu, Ipopt::Number d_norm,
                             Ipopt::Number regularization_size, Ipopt::Number alpha_du, Ipopt::Number alpha_pr,
                             Ipopt::Index ls_trials, const Ipopt::IpoptData* ip_data,
                             Ipopt::IpoptCalculatedQuantities* ip_cq) override;
  void finalize_solution(Ipopt::SolverReturn status, Ipopt::Index n, const Ipopt::Number* x, const Ipopt::Number* z_L,
                         const Ipopt::Number* z_U, Ipopt::Index m, const Ipopt::Number* g, const Ipopt::Number* lambda,
                         Ipopt::Number obj_value, const Ipopt::IpoptData* ip_data,
                         Ipopt::IpoptCalculatedQuantities* ip_cq) override;

 private:
  struct Regularization {
    int offset, count;
    double weight, reference;
  };
  // The objective and constraints at the latest point, for the best
  // feasible point (both must have been evaluated there).
  struct PointRecord {
    VectorXd x;
    bool has_f = false, has_g = false;
    double f = 0;
    VectorXd g;
  };

  void CheckRows(const std::vector<int>& rows, const char* what) const;
  // Column lists of the Jacobian rows (built once).
  void BuildStructure();
  PointRecord& Record(const Eigen::Ref<const VectorXd>& x);
  // Records the point as the best feasible one if it is.
  void ConsiderBest(const PointRecord& record);
  double Violation(const VectorXd& x, const VectorXd& g) const;

  std::unique_ptr<RolloutFunction> function_;
  VectorXd objective_weights_;  // one per row of the function
  std::vector<Regularization> regularization_;
  std::vector<int> constraint_rows_;
  std::vector<double> constraint_lower_, constraint_upper_;
  std::vector<LinearConstraint> linear_;
  VectorXd custom_start_;                      // SetStartingPoint's, or empty
  std::vector<std::vector<int>> row_columns_;  // per constraint row
  int nnz_jac_ = -1;

  PointRecord record_;
  VectorXd best_x_;
  double best_f_ = 0;
  double best_tolerance_ = 1e-6;
  std::vector<IterationRecord> iterations_;
  bool has_solution_ = false;
  Ipopt::SolverReturn solution_status_ = Ipopt::UNASSIGNED;
  VectorXd solution_;
  double solution_objective_ = 0;
};

}  // namespace diffpd::solvers
