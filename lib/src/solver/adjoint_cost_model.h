// The per-step choice of SolverOptions::adjoint_solver = kAuto (internal):
// whether the PD-preconditioned iteration or a direct factorisation of the
// step Hessian H solves the next step's adjoint (or tangent) system, from
// the wall seconds each took on earlier steps of the same problem.
//
// Each solver is measured once first (the iteration, then the
// factorisation); afterwards the one with the smaller estimate (the leader)
// runs, and the other is measured again after
//   max(kMinRecheck, ceil((r - 1) / kRecheckShare))
// of the leader's steps, r being the ratio of their estimates: a recheck
// costs (r - 1) leader steps, so rechecks add at most kRecheckShare to the
// leader's time, and a close race is rechecked every kMinRecheck steps (the
// iteration count follows the state along the rollout). A solver's estimate
// is an average with weight 1/2 over its consecutive measurements (the
// iteration count varies from step to step), restarted at a recheck (older
// measurements may be stale). The direct solve is measured without its
// one-off symbolic analysis.
#pragma once

namespace diffpd::internal {

class AdjointCostModel {
 public:
  enum class Solver { kIterative = 0, kDirect = 1 };
  static constexpr int kMinRecheck = 8;
  static constexpr double kRecheckShare = 0.05;

  // The solver of the next step.
  Solver Next() const;
  // Records the next step's solve by `solver`, taking `seconds`.
  void Record(Solver solver, double seconds);

  bool measured(Solver solver) const { return measured_[Index(solver)]; }
  // Estimated seconds of one step's solve (0 before a measurement).
  double estimate(Solver solver) const { return estimate_[Index(solver)]; }
  // Leader steps between rechecks of the other solver, from the estimates.
  int RecheckInterval() const;

 private:
  static int Index(Solver solver) { return static_cast<int>(solver); }
  // The solver with the smaller estimate (both measured).
  Solver Leader() const;

  bool measured_[2] = {false, false};
  double estimate_[2] = {0, 0};
  bool have_last_ = false;
  Solver last_ = Solver::kIterative;  // the solver of the latest recorded step
  int leader_steps_ = 0;              // the leader's steps since the other was measured
};

}  // namespace diffpd::internal
