#include "diffpd/solvers/mpi/distributed_rollout_set.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

// Terms owned by `rank` among `num_terms` on `size` ranks (t mod size == rank).
int OwnedCount(int num_terms, int size, int rank) { return rank < num_terms ? (num_terms - 1 - rank) / size + 1 : 0; }

// The string `text` of rank `root`, on every rank.
std::string BroadcastString(MPI_Comm comm, int root, std::string text) {
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, root, comm);
  text.resize(length);
  if (length > 0) MPI_Bcast(text.data(), length, MPI_CHAR, root, comm);
  return text;
}

}  // namespace

DistributedRolloutSet::DistributedRolloutSet(MPI_Comm comm, int num_terms, TermObjective objective,
                                             const std::function<RolloutTerm(int)>& make_term)
    : comm_(comm), objective_(objective) {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) throw InvalidInputError("DistributedRolloutSet: MPI is not initialised (call MPI_Init first)");
  if (num_terms < 1)
    throw InvalidInputError("DistributedRolloutSet: num_terms = " + std::to_string(num_terms) +
                            " is invalid: must be >= 1");
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);

  // This rank's terms; a failure is reported by every rank alike below.
  std::string error;
  int failed_term = num_terms;  // none
  for (int t = rank_; t < num_terms; t += size_) {
    try {
      RolloutTerm term = make_term(t);
      CheckRolloutTerm(term);
      local_.push_back(std::move(term));
      local_ids_.push_back(t);
    } catch (const std::exception& e) {
      failed_term = t;
      error = e.what();
      break;
    }
  }
  int first_failed = num_terms;
  MPI_Allreduce(&failed_term, &first_failed, 1, MPI_INT, MPI_MIN, comm_);
  if (first_failed < num_terms) {
    const int owner = first_failed % size_;
    const std::string message = BroadcastString(comm_, owner, error);
    throw InvalidInputError("DistributedRolloutSet: term " + std::to_string(first_failed) + " (rank " +
                            std::to_string(owner) + "): " + message);
  }

  // Rows and parameters of every term, on every rank.
  std::vector<int> mine;
  for (const RolloutTerm& term : local_) {
    mine.push_back(static_cast<int>(term.rows.size()));
    mine.push_back(term.function->num_parameters());
  }
  std::vector<int> counts(size_), displacements(size_);
  for (int r = 0, offset = 0; r < size_; ++r) {
    counts[r] = 2 * OwnedCount(num_terms, size_, r);
    displacements[r] = offset;
    offset += counts[r];
  }
  std::vector<int> all(2 * num_terms);
  MPI_Allgatherv(mine.data(), static_cast<int>(mine.size()), MPI_INT, all.data(), counts.data(), displacements.data(),
                 MPI_INT, comm_);
  rows_.assign(num_terms, 0);
  std::vector<int> parameters(num_terms, 0);
  for (int r = 0; r < size_; ++r)
    for (int i = 0; i < counts[r] / 2; ++i) {
      const int t = r + i * size_;
      rows_[t] = all[displacements[r] + 2 * i];
      parameters[t] = all[displacements[r] + 2 * i + 1];
    }
  num_parameters_ = parameters[0];
  for (int t = 0; t < num_terms; ++t) {
    if (parameters[t] != num_parameters_) {
      std::ostringstream msg;
      msg << "DistributedRolloutSet: term " << t << " has " << parameters[t] << " parameters, term 0 has "
          << num_parameters_;
      throw InvalidInputError(msg.str());
    }
    num_rows_ += rows_[t];
  }
}

DistributedRolloutSet::~DistributedRolloutSet() {
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (!finalised) Stop();
}

void DistributedRolloutSet::Stop() {
  if (!is_root() || stopped_) return;
  stopped_ = true;
  int command = kStop;
  MPI_Bcast(&command, 1, MPI_INT, 0, comm_);
}

void DistributedRolloutSet::Serve() {
  if (is_root()) throw InvalidInputError("DistributedRolloutSet: Serve is called on rank 0, which evaluates");
  VectorXd p(num_parameters_);
  std::vector<double> unused;
  std::string error;
  for (;;) {
    int command = kStop;
    MPI_Bcast(&command, 1, MPI_INT, 0, comm_);
    if (command == kStop) return;
    Round(command, &p, &unused, &error);
  }
}

int DistributedRolloutSet::TermRecordSize(int command, int term) const {
  switch (command) {
    case kEvaluate:
      return 1 + rows_[term];
    case kEvaluateWithJacobian:
      return 1 + rows_[term] * (1 + num_parameters_);
    default:  // kGradient
      return 2 + num_parameters_;
  }
}

void DistributedRolloutSet::Round(int command, VectorXd* p, std::vector<double>* gathered, std::string* error) {
  MPI_Bcast(p->data(), num_parameters_, MPI_DOUBLE, 0, comm_);

  // This rank's records: [ok, values (, Jacobian column-major)] or [ok, value, gradient].
  std::vector<double> records;
  std::string first_error;
  bool failed = false;
  for (size_t i = 0; i < local_.size(); ++i) {
    const int t = local_ids_[i];
    const size_t start = records.size();
    records.resize(start + TermRecordSize(command, t), 0.0);
    if (failed) continue;  // as a LocalRolloutSet: nothing after the first failure
    std::string term_error;
    bool ok;
    if (command == kGradient) {
      VectorXd g;
      double value = 0;
      ok = RolloutTermGradient(&local_[i], objective_, *p, &g, &value, &term_error);
      if (ok) {
        records[start + 1] = value;
        Eigen::Map<VectorXd>(records.data() + start + 2, num_parameters_) = g;
      }
    } else {
      VectorXd v;
      MatrixXd j;
      const bool jacobian = command == kEvaluateWithJacobian;
      ok = EvaluateRolloutTerm(&local_[i], *p, &v, jacobian ? &j : nullptr, &term_error);
      if (ok) {
        Eigen::Map<VectorXd>(records.data() + start + 1, rows_[t]) = v;
        if (jacobian) Eigen::Map<MatrixXd>(records.data() + start + 1 + rows_[t], rows_[t], num_parameters_) = j;
      }
    }
    records[start] = ok ? 1.0 : 0.0;
    if (!ok) {
      failed = true;
      first_error = "term " + std::to_string(t) + ": " + term_error;
    }
  }

  // Gather the records (rank order) and the ranks' first errors on rank 0.
  const std::vector<int> offsets = RecordOffsets(command);
  std::vector<int> counts(size_, 0), displacements(size_, 0);
  for (int t = 0; t < num_terms(); ++t) counts[t % size_] += TermRecordSize(command, t);
  for (int r = 1; r < size_; ++r) displacements[r] = displacements[r - 1] + counts[r - 1];
  if (is_root()) gathered->assign(displacements[size_ - 1] + counts[size_ - 1], 0.0);
  MPI_Gatherv(records.data(), static_cast<int>(records.size()), MPI_DOUBLE, is_root() ? gathered->data() : nullptr,
              counts.data(), displacements.data(), MPI_DOUBLE, 0, comm_);
  int length = static_cast<int>(first_error.size());
  std::vector<int> lengths(size_, 0), starts(size_, 0);
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, comm_);
  for (int r = 1; r < size_; ++r) starts[r] = starts[r - 1] + lengths[r - 1];
  std::string messages(is_root() ? starts[size_ - 1] + lengths[size_ - 1] : 0, ' ');
  MPI_Gatherv(first_error.data(), length, MPI_CHAR, is_root() ? messages.data() : nullptr, lengths.data(),
              starts.data(), MPI_CHAR, 0, comm_);
  if (!is_root()) return;
  // The first failing term's message: its owner's first error.
  error->clear();
  for (int t = 0; t < num_terms(); ++t)
    if ((*gathered)[offsets[t]] == 0.0) {
      const int owner = t % size_;
      *error = messages.substr(starts[owner], lengths[owner]);
      break;
    }
}

std::vector<int> DistributedRolloutSet::RecordOffsets(int command) const {
  // Rank r's records follow those of ranks 0..r-1; within a rank, its terms in order.
  std::vector<int> rank_start(size_ + 1, 0);
  for (int t = 0; t < num_terms(); ++t) rank_start[t % size_ + 1] += TermRecordSize(command, t);
  for (int r = 0; r < size_; ++r) rank_start[r + 1] += rank_start[r];
  std::vector<int> offsets(num_terms());
  for (int t = 0; t < num_terms(); ++t) {
    offsets[t] = rank_start[t % size_];
    rank_start[t % size_] += TermRecordSize(command, t);
  }
  return offsets;
}

bool DistributedRolloutSet::RootRound(int command, const char* what, const Eigen::Ref<const VectorXd>& p,
                                      std::vector<double>* gathered) {
  if (!is_root()) {
    last_error_ = std::string("DistributedRolloutSet: ") + what + " is called on rank " + std::to_string(rank_) +
                  "; only rank 0 evaluates (the others Serve)";
    return false;
  }
  if (stopped_) {
    last_error_ = std::string("DistributedRolloutSet: ") + what + " after Stop";
    return false;
  }
  if (p.size() != num_parameters_) {
    last_error_ = "DistributedRolloutSet: p has " + std::to_string(p.size()) + " entries, expected " +
                  std::to_string(num_parameters_);
    return false;
  }
  MPI_Bcast(&command, 1, MPI_INT, 0, comm_);
  VectorXd point = p;
  std::string error;
  Round(command, &point, gathered, &error);
  if (!error.empty()) last_error_ = error;
  return error.empty();
}

bool DistributedRolloutSet::Evaluate(const Eigen::Ref<const VectorXd>& p, VectorXd* values, MatrixXd* jacobian) {
  const int command = jacobian ? kEvaluateWithJacobian : kEvaluate;
  std::vector<double> gathered;
  if (!RootRound(command, "Evaluate", p, &gathered)) return false;
  values->resize(num_rows_);
  if (jacobian) jacobian->resize(num_rows_, num_parameters_);
  const std::vector<int> offsets = RecordOffsets(command);
  for (int t = 0, row = 0; t < num_terms(); ++t) {
    const double* record = gathered.data() + offsets[t];
    values->segment(row, rows_[t]) = Eigen::Map<const VectorXd>(record + 1, rows_[t]);
    if (jacobian)
      jacobian->middleRows(row, rows_[t]) =
          Eigen::Map<const MatrixXd>(record + 1 + rows_[t], rows_[t], num_parameters_);
    row += rows_[t];
  }
  return true;
}

bool DistributedRolloutSet::Gradient(const Eigen::Ref<const VectorXd>& p, VectorXd* gradient, double* value) {
  const int command = kGradient;
  std::vector<double> gathered;
  if (!RootRound(command, "Gradient", p, &gathered)) return false;
  // Summed in term order, as LocalRolloutSet does.
  *gradient = VectorXd::Zero(num_parameters_);
  double sum = 0;
  const std::vector<int> offsets = RecordOffsets(command);
  for (int t = 0; t < num_terms(); ++t) {
    const double* record = gathered.data() + offsets[t];
    *gradient += Eigen::Map<const VectorXd>(record + 2, num_parameters_);
    sum += record[1];
  }
  if (value) *value = sum;
  return true;
}

VectorXd DistributedRolloutSet::initial_parameters() const {
  return local_.empty() ? VectorXd() : local_[0].function->initial_parameters();
}
VectorXd DistributedRolloutSet::lower_bounds() const {
  return local_.empty() ? VectorXd() : local_[0].function->lower_bounds();
}
VectorXd DistributedRolloutSet::upper_bounds() const {
  return local_.empty() ? VectorXd() : local_[0].function->upper_bounds();
}

RolloutStatistics DistributedRolloutSet::statistics() const {
  RolloutStatistics total;
  for (const RolloutTerm& t : local_) total = total + t.function->statistics();
  return total;
}

}  // namespace diffpd::solvers
