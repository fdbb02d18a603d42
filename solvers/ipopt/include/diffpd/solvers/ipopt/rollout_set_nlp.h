// An Ipopt nonlinear program over a RolloutSet's scalar loss
// (diffpd/solvers/core/rollout_set.h; Ipopt 3.11 TNLP):
//
//   min_p  L(p) = sum_t L_t(p)      s.t.  lower <= p <= upper,
//
// L_t = sum of term t's rows (TermObjective::kSum) or 1/2 |v_t|^2
// (kLeastSquares), the bounds and the starting point the set's. No
// constraints. The gradient is exact: RolloutSet::Gradient, one adjoint pass
// per term; no Hessian (SolveWithIpopt, ipopt_solve.h, runs Ipopt with a
// limited-memory one). The same program runs over a LocalRolloutSet or, on
// rank 0, over a DistributedRolloutSet.
//
// Per evaluation point, eval_f costs the terms' rollouts (RolloutSet::Value)
// and eval_grad_f their adjoint passes; each term's rollout function caches
// its rollout, so a gradient at a point whose value was asked for simulates
// nothing again. A failed term makes eval_* return false (Ipopt cuts its
// step), the reason in last_error(). Nothing throws through Ipopt.
//
// Create with `new` and hold in an Ipopt::SmartPtr when handing it to Ipopt.
#pragma once

#include <IpTNLP.hpp>

#include <string>
#include <vector>

#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::solvers {

class RolloutSetNlp : public Ipopt::TNLP {
 public:
  // Does not take ownership of `set`, which must outlive this object.
  // Throws InvalidInputError if it is null.
  explicit RolloutSetNlp(RolloutSet* set);

  RolloutSet& set() { return *set_; }
  int num_variables() const { return set_->num_parameters(); }
  VectorXd starting_point() const { return set_->initial_parameters(); }

  // The evaluations of the TNLP methods, for callers outside Ipopt; false
  // on failure (the reason in last_error()).
  bool Objective(const VectorXd& p, double* f);
  bool ObjectiveGradient(const VectorXd& p, VectorXd* gradient);
  // Largest violation of the bounds at p (>= 0).
  double BoundViolation(const VectorXd& p) const;
  const std::string& last_error() const { return set_->last_error(); }

  // Objective per Ipopt iteration (0 = start), as intermediate_callback saw it.
  const std::vector<double>& objective_history() const { return objective_history_; }
  // What finalize_solution reported (valid once Ipopt has finished).
  bool has_solution() const { return has_solution_; }
  const VectorXd& solution() const { return solution_; }

  // ---- Ipopt::TNLP ----
  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override;
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m, Ipopt::Number* g_l,
                       Ipopt::Number* g_u) override;
  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number* z_L,
                          Ipopt::Number* z_U, Ipopt::Index m, bool init_lambda, Ipopt::Number* lambda) override;
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
  RolloutSet* set_;
  std::vector<double> objective_history_;
  bool has_solution_ = false;
  VectorXd solution_;
};

}  // namespace diffpd::solvers
