// A RolloutSet (diffpd/solvers/core/rollout_set.h) whose terms are spread
// over the ranks of an MPI communicator: term t lives on rank t mod size.
// Rank 0 runs the optimiser and calls Evaluate / Gradient; every other rank
// calls Serve(), which answers rank 0's evaluations until rank 0 calls
// Stop(). Per evaluation, rank 0 broadcasts p (N doubles), each rank
// computes its terms (EvaluateRolloutTerm / RolloutTermGradient) and rank 0
// gathers, per term, its rows and Jacobian (rows x N) or its value and
// gradient (N), and combines them in term order: the results equal a
// LocalRolloutSet's over the same terms bit for bit.
//
//   MPI_Init(&argc, &argv);          // the program initialises MPI
//   DistributedRolloutSet set(MPI_COMM_WORLD, 4, TermObjective::kLeastSquares,
//                             [&](int t) { return MakeTerm(t); });   // only this rank's terms
//   if (set.is_root()) {
//     ... ceres::Solve over RolloutSetCostFunction(&set) ...
//     set.Stop();
//   } else {
//     set.Serve();
//   }
//
// Cost per evaluation on R ranks: max over ranks of its terms' time, plus a
// broadcast of N doubles and a gather of sum_t rows_t (N + 1) doubles
// (docs/distributed.md).
//
// Errors: the constructor is collective and throws InvalidInputError on
// every rank alike when a rank's make_term throws or the terms disagree
// ("DistributedRolloutSet: term 3 (rank 1): <message>", "DistributedRolloutSet:
// term 1 has 3 parameters, term 0 has 2"); when MPI is not initialised; or
// for num_terms < 1. Evaluate and Gradient never throw: false, with the
// first failing term's reason in last_error(), on rank 0; on another rank
// they return false ("... is called on rank 1; only rank 0 evaluates").
// Threads: each rank's simulations use their SolverOptions::num_threads; MPI
// is called from the calling thread only (MPI_THREAD_FUNNELED suffices).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <mpi.h>

#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::solvers {

class DistributedRolloutSet : public RolloutSet {
 public:
  // Collective over `comm` (every rank calls it with the same num_terms and
  // objective). make_term(t) is called on the owning rank of each term t.
  DistributedRolloutSet(MPI_Comm comm, int num_terms, TermObjective objective,
                        const std::function<RolloutTerm(int)>& make_term);
  // Rank 0: Stop() if not done (the other ranks must be in Serve()).
  ~DistributedRolloutSet() override;
  DistributedRolloutSet(const DistributedRolloutSet&) = delete;
  DistributedRolloutSet& operator=(const DistributedRolloutSet&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }
  // The terms this rank owns (t with t mod size == rank), in order.
  const std::vector<int>& local_terms() const { return local_ids_; }

  // Ranks other than 0: answers rank 0's evaluations until it calls Stop().
  // Throws InvalidInputError on rank 0.
  void Serve();
  // Rank 0: releases the ranks in Serve(). Idempotent; nothing elsewhere.
  void Stop();

  int num_terms() const override { return static_cast<int>(rows_.size()); }
  int num_parameters() const override { return num_parameters_; }
  int term_rows(int t) const override { return rows_.at(t); }
  int num_rows() const override { return num_rows_; }
  TermObjective objective() const override { return objective_; }
  // Term 0's (held by rank 0); on other ranks, their first term's.
  VectorXd initial_parameters() const override;
  VectorXd lower_bounds() const override;
  VectorXd upper_bounds() const override;
  bool Evaluate(const Eigen::Ref<const VectorXd>& p, VectorXd* values, MatrixXd* jacobian) override;
  bool Gradient(const Eigen::Ref<const VectorXd>& p, VectorXd* gradient, double* value) override;
  const std::string& last_error() const override { return last_error_; }
  // This rank's terms only.
  RolloutStatistics statistics() const override;

 private:
  enum Command : int { kStop = 0, kEvaluate = 1, kEvaluateWithJacobian = 2, kGradient = 3 };
  // One collective round: command and p broadcast from rank 0, the local
  // terms computed, their results gathered on rank 0 into `gathered` (in
  // rank order) and the first failure's message into `error`.
  void Round(int command, VectorXd* p, std::vector<double>* gathered, std::string* error);
  // Doubles per term in a round's buffer.
  int TermRecordSize(int command, int term) const;
  // Where each term's record starts in a round's gathered buffer.
  std::vector<int> RecordOffsets(int command) const;
  // Rank 0's side of a round (`what`: "Evaluate" or "Gradient"); false with
  // last_error_ set off rank 0, after Stop, for a p of the wrong size or a
  // failed term.
  bool RootRound(int command, const char* what, const Eigen::Ref<const VectorXd>& p, std::vector<double>* gathered);

  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
  TermObjective objective_;
  std::vector<RolloutTerm> local_;  // this rank's terms
  std::vector<int> local_ids_;      // their indices
  std::vector<int> rows_;           // rows per term (all terms)
  int num_rows_ = 0;
  int num_parameters_ = 0;
  bool stopped_ = false;
  std::string last_error_;
};

}  // namespace diffpd::solvers
