// An Ipopt nonlinear program over a differentiable rollout (Ipopt 3.11 TNLP):
//
//   min_x   sum_t w_t F_t(rollout(x)) + sum_r (w_r / 2) |x_r - ref_r|^2
//   s.t.    lower_c <= G_c(rollout(x)) <= upper_c     (trajectory constraints)
//           lower_l <= a_l . x <= upper_l              (linear constraints)
//           x_lower <= x <= x_upper                    (variable bounds)
//
// x is the concatenation of blocks of decision variables
// (control_variables.h); rollout(x) simulates the setup the blocks write,
// with the simulator's method. Constraint order: trajectory constraints in
// the order added, then linear constraints in the order added.
//
// Derivatives, all exact to the simulator's tolerances:
//  - objective gradient: one reverse-mode pass (Simulator::Backward) per point;
//  - constraint Jacobian, chosen by size (ConstraintJacobianMode::kAuto):
//    reverse mode, one Backward per trajectory constraint, each over the
//    rollout truncated after the constraint's last state (a constraint at
//    step k costs k adjoint steps); or forward mode, one Simulator::Tangents
//    pass with one direction per variable (all directions share each step's
//    linearisation), used when the variables are fewer than the trajectory
//    constraints and forward mode covers the problem: every block supports
//    it (not muscle activations) and the scene has no term the tangent pass
//    leaves out (frictional or penalty contact, muscles, hydrodynamics,
//    damping). ResolvedJacobianMode() says which mode is used.
//  - Hessian: none; run Ipopt with hessian_approximation = limited-memory
//    (ipopt_solve.h sets it).
// Jacobian sparsity is declared honestly: a trajectory constraint whose last
// state is k has an entry for variable j iff the block says j can influence
// some state <= k (FirstAffectedState(j) <= k), so per-step controls after a
// path constraint's step are structurally zero; linear rows list their own
// columns. Everything else in a row is dense.
//
// One rollout per evaluation point: the first eval_* call at a new x
// simulates once (and keeps the rollout); f, grad f, g and the Jacobian at
// that x reuse it. The cache is keyed on the values of x, which honours
// Ipopt's new_x flag (new_x = false always hits the cache) and never serves
// a stale rollout. A failed rollout or adjoint (SolverError, or any other
// exception) makes eval_* return false, so Ipopt cuts its step; the message
// is kept in last_error(). Nothing throws through Ipopt.
//
// Create with `new` and hold in an Ipopt::SmartPtr when handing it to Ipopt
// (Ipopt reference-counts it); tests may also call the TNLP methods directly
// on a stack object.
#pragma once

#include <IpTNLP.hpp>

#include <memory>
#include <string>
#include <vector>

#include "diffpd/simulator.h"
#include "diffpd/solvers/control_variables.h"
#include "diffpd/solvers/linear_constraint.h"
#include "diffpd/solvers/core/trajectory_function.h"

namespace diffpd::solvers {

// Counters and timings of a RolloutNlp (cumulative since construction).
struct RolloutNlpStatistics {
  long rollouts = 0;            // forward simulations (one per evaluation point)
  long failed_rollouts = 0;     // those that threw (eval_* returned false)
  long backward_passes = 0;     // derivative passes: adjoints (objective, constraints) and tangent passes
  long tangent_passes = 0;      // of which forward-mode tangent passes
  double forward_seconds = 0;   // wall time in Simulator::Simulate
  double backward_seconds = 0;  // wall time in Simulator::Backward and Simulator::Tangents
};

// How the constraint Jacobian is computed (see the file comment).
enum class ConstraintJacobianMode {
  kAuto,     // forward if available and num_variables < trajectory constraints, else reverse
  kReverse,  // one adjoint pass per trajectory constraint
  kForward,  // one tangent pass; evaluation fails (returns false) where unavailable
};
const char* ToString(ConstraintJacobianMode mode);

// One Ipopt iteration as reported to intermediate_callback.
struct IterationRecord {
  int iteration = 0;
  double objective = 0;
  double primal_infeasibility = 0;  // Ipopt's inf_pr (max constraint violation, scaled problem)
  bool restoration = false;         // Ipopt was in its restoration phase
};

class RolloutNlp : public Ipopt::TNLP {
 public:
  // `simulator` is not owned and must outlive the NLP; the NLP sets its
  // material for every rollout. `base` holds K >= 1 inputs and an initial
  // state of the simulator's size. Throws InvalidInputError otherwise.
  RolloutNlp(Simulator* simulator, RolloutSetup base);
  ~RolloutNlp() override;

  // Appends a block of variables; returns the index of its first variable.
  // Throws InvalidInputError if the block does not fit the rollout.
  int AddVariables(std::unique_ptr<ControlVariables> block);
  // Adds weight * F to the objective.
  void AddObjective(std::unique_ptr<TrajectoryFunction> f, double weight = 1.0);
  // Adds (weight / 2) |x[offset .. offset+count) - reference|^2.
  void AddRegularization(int offset, int count, double weight, double reference = 0.0);
  // lower <= G <= upper (lower == upper: equality; +-infinity: one-sided).
  void AddConstraint(std::unique_ptr<TrajectoryFunction> g, double lower, double upper);
  void AddLinearConstraint(LinearConstraint c);
  // Replaces the starting point (default: the blocks' initial values,
  // which it also becomes again when a block is added afterwards).
  // Throws InvalidInputError on a size mismatch or a non-finite entry.
  void SetStartingPoint(const VectorXd& x);

  void SetJacobianMode(ConstraintJacobianMode mode) { jacobian_mode_ = mode; }
  // True if forward mode covers this problem (see the file comment).
  bool ForwardModeAvailable() const;
  // kForward or kReverse: what kAuto resolves to, or the mode set.
  ConstraintJacobianMode ResolvedJacobianMode() const;

  int num_variables() const { return static_cast<int>(lower_.size()); }
  int num_constraints() const;
  const VectorXd& starting_point() const;
  const ControlVariables& block(int b) const { return *blocks_[b].block; }
  int num_blocks() const { return static_cast<int>(blocks_.size()); }
  Simulator& simulator() { return *sim_; }

  // The same evaluations as the TNLP methods, for callers outside Ipopt.
  // Each returns false (and sets last_error()) on a failed rollout/adjoint.
  bool Objective(const VectorXd& x, double* f);
  bool ObjectiveGradient(const VectorXd& x, VectorXd* grad);
  bool Constraints(const VectorXd& x, VectorXd* g);
  // Dense m x n Jacobian (structural zeros included as 0).
  bool ConstraintJacobian(const VectorXd& x, MatrixXd* jacobian);
  // The rollout at x (simulated if not cached); nullptr on failure.
  const Rollout* RolloutAt(const VectorXd& x);
  // The setup the blocks make at x.
  RolloutSetup SetupAt(const VectorXd& x) const;
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

  const RolloutNlpStatistics& statistics() const { return stats_; }
  const std::vector<IterationRecord>& iterations() const { return iterations_; }
  const std::string& last_error() const { return last_error_; }
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
  struct Block {
    std::unique_ptr<ControlVariables> block;
    int offset;
  };
  struct Term {
    std::unique_ptr<TrajectoryFunction> f;
    double weight;
  };
  struct Regularization {
    int offset, count;
    double weight, reference;
  };
  struct TrajectoryConstraint {
    std::unique_ptr<TrajectoryFunction> g;
    double lower, upper;
  };
  struct Cache;

  // Makes the cache hold x's rollout; false if it failed.
  bool Update(const Ipopt::Number* x, bool new_x);
  bool ComputeObjective();
  bool ComputeGradient();
  bool ComputeConstraints();
  bool ComputeJacobian();
  void JacobianReverse(std::vector<double>* values);
  void JacobianForward(std::vector<double>* values);
  // Gradient of `terms` weighted over the rollout truncated after state
  // `last`, pulled back onto every variable (added into out).
  void PullBackLoss(const LossGradient& loss, int last, Eigen::Ref<VectorXd> out);
  // Column lists of the Jacobian rows (built once).
  void BuildStructure();
  // Records the cached point as the best feasible one if it is.
  void ConsiderBest();
  template <typename Fn>
  bool Guarded(const char* what, Fn&& fn);

  Simulator* sim_;
  RolloutSetup base_;
  std::vector<Block> blocks_;
  std::vector<int> block_of_;  // variable -> block
  VectorXd lower_, upper_;
  VectorXd block_start_;   // the blocks' initial values
  VectorXd custom_start_;  // SetStartingPoint's, or empty
  std::vector<Term> objective_;
  std::vector<Regularization> regularization_;
  std::vector<TrajectoryConstraint> constraints_;
  std::vector<LinearConstraint> linear_;
  std::vector<std::vector<int>> row_columns_;  // per constraint row
  int nnz_jac_ = -1;
  ConstraintJacobianMode jacobian_mode_ = ConstraintJacobianMode::kAuto;

  std::unique_ptr<Cache> cache_;
  VectorXd best_x_;
  double best_f_ = 0;
  double best_tolerance_ = 1e-6;
  RolloutNlpStatistics stats_;
  std::vector<IterationRecord> iterations_;
  std::string last_error_;
  bool has_solution_ = false;
  Ipopt::SolverReturn solution_status_ = Ipopt::UNASSIGNED;
  VectorXd solution_;
  double solution_objective_ = 0;
};

}  // namespace diffpd::solvers
