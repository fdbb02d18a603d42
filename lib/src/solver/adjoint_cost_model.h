// The per-step choice of SolverOptions::adjoint_solver = kAuto (internal):
// whether the PD-preconditioned iteration or a direct factorisation of the
// step Hessian H solves the next step's adjoint (or tangent) system, from
// deterministic cost estimates (adjoint_work.h): the iteration's from the
// operations its latest steps counted (Hessian products, solves with A's
// factor, iterations), the factorisation's from the sizes of its factor,
// known before it runs. No clock enters, so the choice depends on the
// problem alone (not on the machine's load), and no factorisation is made
// only to be measured.
//
// The first step iterates (its counts are the iteration's first estimate).
// Afterwards the factorisation runs where its estimate is below the
// iteration's by more than kDirectMargin (the estimates' error on the
// problems they were fitted to; in a closer race the iteration keeps the
// steps, as a switch would save less than the estimates can tell apart),
// else the iteration. While the iteration
// leads, the factorisation's estimate (fixed by the factor's size) needs no
// recheck. While the factorisation leads, the iteration's estimate, which
// follows the state along the rollout, is measured again after
//   max(kMinRecheck, ceil((r - 1) / kRecheckShare))
// direct steps, r the ratio of the estimates: a recheck costs (r - 1)
// direct steps, so rechecks add at most kRecheckShare to the direct steps'
// cost. The iteration's estimate is an average with weight 1/2 over its
// consecutive steps, restarted at a recheck.
#pragma once

namespace diffpd::internal {

class AdjointCostModel {
 public:
  enum class Solver { kIterative = 0, kDirect = 1 };
  static constexpr int kMinRecheck = 8;
  static constexpr double kRecheckShare = 0.05;
  static constexpr double kDirectMargin = 0.10;

  // The estimated cost of the next step's direct solve (seconds, > 0; its
  // one-off analysis included where still to come). Unset or <= 0: the
  // direct solve is not a candidate.
  void SetDirectEstimate(double seconds) { direct_estimate_ = seconds; }
  // The solver of the next step.
  Solver Next() const;
  // Records the next step's solve by `solver`; `seconds` is the iteration's
  // estimated cost from its counts (ignored for the direct solve).
  void Record(Solver solver, double seconds);

  bool measured_iteration() const { return measured_iteration_; }
  // Estimated seconds of one step's iteration (0 before a measurement).
  double iteration_estimate() const { return iteration_estimate_; }
  double direct_estimate() const { return direct_estimate_; }
  // Whether the factorisation leads: both estimated, and direct x (1 +
  // kDirectMargin) < iteration.
  bool DirectLeads() const;
  // Direct steps between rechecks of the iteration, from the estimates.
  int RecheckInterval() const;

 private:
  bool measured_iteration_ = false;
  double iteration_estimate_ = 0;
  double direct_estimate_ = 0;
  bool last_iterative_ = false;  // the latest recorded step iterated
  int direct_steps_ = 0;         // direct steps since the latest iteration
};

}  // namespace diffpd::internal
