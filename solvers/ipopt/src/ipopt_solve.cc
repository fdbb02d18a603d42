#include "diffpd/solvers/ipopt/ipopt_solve.h"

#include <IpJournalist.hpp>

#include <algorithm>

#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

// Keeps everything Ipopt prints (at the journal's levels) and echoes it.
class CaptureJournal : public Ipopt::Journal {
 public:
  CaptureJournal(Ipopt::EJournalLevel level, FILE* echo) : Ipopt::Journal("diffpd_capture", level), echo_(echo) {}
  const std::string& text() const { return text_; }

 protected:
  void PrintImpl(Ipopt::EJournalCategory, Ipopt::EJournalLevel, const char* str) override {
    text_ += str;
    if (echo_) std::fputs(str, echo_);
  }
  void PrintfImpl(Ipopt::EJournalCategory, Ipopt::EJournalLevel, const char* format, va_list ap) override {
    va_list copy;
    va_copy(copy, ap);
    const int size = std::vsnprintf(nullptr, 0, format, copy);
    va_end(copy);
    if (size <= 0) return;
    std::string line(static_cast<size_t>(size) + 1, '\0');
    std::vsnprintf(line.data(), line.size(), format, ap);
    line.resize(static_cast<size_t>(size));
    text_ += line;
    if (echo_) std::fputs(line.c_str(), echo_);
  }
  void FlushBufferImpl() override {
    if (echo_) std::fflush(echo_);
  }

 private:
  std::string text_;
  FILE* echo_;
};

template <typename T>
void SetOption(Ipopt::OptionsList* list, const std::string& name, const T& value) {
  bool ok;
  if constexpr (std::is_same_v<T, std::string>)
    ok = list->SetStringValue(name, value);
  else if constexpr (std::is_same_v<T, int>)
    ok = list->SetIntegerValue(name, value);
  else
    ok = list->SetNumericValue(name, value);
  if (!ok) {
    std::ostringstream msg;
    msg << "Ipopt option " << name << " = " << value << " is invalid (unknown option, wrong type or out of range; "
        << "see the Ipopt options reference)";
    throw InvalidInputError(msg.str());
  }
}

int ParseDerivativeCheck(const std::string& log) {
  if (log.find("No errors detected by derivative checker.") != std::string::npos) return 0;
  const std::string key = "Derivative checker detected ";
  const size_t at = log.rfind(key);
  if (at == std::string::npos) return -1;
  return std::atoi(log.c_str() + at + key.size());
}

// An application with the adapter's defaults and `options`, its output
// captured by *journal; *status is Initialize's.
Ipopt::SmartPtr<Ipopt::IpoptApplication> MakeApplication(const IpoptOptions& options,
                                                         Ipopt::SmartPtr<CaptureJournal>* journal_out,
                                                         Ipopt::ApplicationReturnStatus* status) {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = new Ipopt::IpoptApplication(/*create_console_out=*/false);
  int print_level = 5;
  for (const auto& [name, value] : options.int_options)
    if (name == "print_level") print_level = value;
  if (print_level < Ipopt::J_NONE || print_level > Ipopt::J_LAST_LEVEL - 1) {
    std::ostringstream msg;
    msg << "Ipopt option print_level = " << print_level << " is invalid: must be in [0, 12]";
    throw InvalidInputError(msg.str());
  }
  Ipopt::SmartPtr<CaptureJournal> journal =
      new CaptureJournal(static_cast<Ipopt::EJournalLevel>(print_level), options.echo);
  journal->SetAllPrintLevels(static_cast<Ipopt::EJournalLevel>(print_level));
  app->Jnlst()->AddJournal(Ipopt::GetRawPtr(journal));

  Ipopt::OptionsList* list = Ipopt::GetRawPtr(app->Options());
  SetOption(list, "hessian_approximation", std::string("limited-memory"));
  SetOption(list, "print_level", 5);
  SetOption(list, "sb", std::string("yes"));
  for (const auto& [name, value] : options.string_options) SetOption(list, name, value);
  for (const auto& [name, value] : options.int_options) SetOption(list, name, value);
  for (const auto& [name, value] : options.num_options) SetOption(list, name, value);

  std::istringstream no_option_file;  // never read ipopt.opt from the working directory
  *status = app->Initialize(no_option_file);
  *journal_out = journal;
  return app;
}

}  // namespace

const char* ToString(Ipopt::ApplicationReturnStatus status) {
  switch (status) {
    case Ipopt::Solve_Succeeded:
      return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level:
      return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected:
      return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates:
      return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop:
      return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found:
      return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded:
      return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed:
      return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation:
      return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded:
      return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
      return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition:
      return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option:
      return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected:
      return "Invalid_Number_Detected";
    case Ipopt::Unrecoverable_Exception:
      return "Unrecoverable_Exception";
    case Ipopt::NonIpopt_Exception_Thrown:
      return "NonIpopt_Exception_Thrown";
    case Ipopt::Insufficient_Memory:
      return "Insufficient_Memory";
    case Ipopt::Internal_Error:
      return "Internal_Error";
  }
  return "Unknown_Ipopt_Status";
}

bool IpoptSummary::succeeded() const {
  return status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
}

bool IpoptSummary::infeasible() const { return status == Ipopt::Infeasible_Problem_Detected; }

std::string IpoptSummary::BriefReport() const {
  char line[512];
  std::snprintf(line, sizeof(line),
                "%s: objective %.6e (from %.6e), constraint violation %.3e, %d iterations, %ld rollouts, "
                "%ld derivative passes, forward %.3f s, backward %.3f s",
                status_name.c_str(), objective, initial_objective, constraint_violation, iterations, evaluations,
                backward_passes, forward_seconds, backward_seconds);
  return returned_best_feasible ? std::string(line) + " (best feasible point visited)" : std::string(line);
}

IpoptSummary SolveWithIpopt(const Ipopt::SmartPtr<RolloutNlp>& nlp, const IpoptOptions& options) {
  if (!Ipopt::IsValid(nlp)) throw InvalidInputError("SolveWithIpopt: the NLP is null");
  const auto start = std::chrono::steady_clock::now();
  Ipopt::SmartPtr<CaptureJournal> journal;
  Ipopt::ApplicationReturnStatus status;
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = MakeApplication(options, &journal, &status);
  IpoptSummary summary;

  const RolloutStatistics before = nlp->statistics();
  const size_t first_iteration = nlp->iterations().size();
  const VectorXd x0 = nlp->starting_point();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!nlp->Objective(x0, &summary.initial_objective)) summary.initial_objective = nan;
  constexpr double kFeasibility = 1e-6;
  nlp->ResetBestFeasible(kFeasibility);
  if (status == Ipopt::Solve_Succeeded) status = app->OptimizeTNLP(Ipopt::GetRawPtr(nlp));

  summary.status = status;
  summary.status_name = ToString(status);
  summary.x = nlp->has_solution() && nlp->solution().size() == x0.size() ? nlp->solution() : x0;
  if (!nlp->Objective(summary.x, &summary.objective)) summary.objective = nan;
  summary.constraint_violation = nlp->ConstraintViolation(summary.x);
  const bool success = status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
  if (!success && nlp->has_best_feasible() &&
      (!(summary.constraint_violation <= kFeasibility) || !(summary.objective <= nlp->best_feasible_objective()))) {
    summary.x = nlp->best_feasible_x();
    summary.returned_best_feasible = true;
    if (!nlp->Objective(summary.x, &summary.objective)) summary.objective = nan;
    summary.constraint_violation = nlp->ConstraintViolation(summary.x);
  }
  const RolloutStatistics& after = nlp->statistics();
  summary.evaluations = after.rollouts - before.rollouts;
  summary.backward_passes =
      (after.adjoint_passes + after.tangent_passes) - (before.adjoint_passes + before.tangent_passes);
  summary.forward_seconds = after.forward_seconds - before.forward_seconds;
  summary.backward_seconds = after.backward_seconds - before.backward_seconds;
  for (size_t i = first_iteration; i < nlp->iterations().size(); ++i) {
    const IterationRecord& r = nlp->iterations()[i];
    summary.objective_history.push_back(r.objective);
    summary.iterations = r.iteration;
  }
  summary.log = journal->text();
  summary.derivative_checker_errors = ParseDerivativeCheck(summary.log);
  summary.last_error = nlp->last_error();
  summary.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

IpoptSummary SolveRolloutSetWithIpopt(const Ipopt::SmartPtr<RolloutSetNlp>& nlp, const IpoptOptions& options) {
  if (!Ipopt::IsValid(nlp)) throw InvalidInputError("SolveRolloutSetWithIpopt: the NLP is null");
  const auto start = std::chrono::steady_clock::now();
  Ipopt::SmartPtr<CaptureJournal> journal;
  Ipopt::ApplicationReturnStatus status;
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = MakeApplication(options, &journal, &status);
  IpoptSummary summary;
  const RolloutStatistics before = nlp->set().statistics();
  const size_t first_iteration = nlp->objective_history().size();
  const VectorXd x0 = nlp->starting_point();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!nlp->Objective(x0, &summary.initial_objective)) summary.initial_objective = nan;
  if (status == Ipopt::Solve_Succeeded) status = app->OptimizeTNLP(Ipopt::GetRawPtr(nlp));

  summary.status = status;
  summary.status_name = ToString(status);
  summary.x = nlp->has_solution() && nlp->solution().size() == x0.size() ? nlp->solution() : x0;
  if (!nlp->Objective(summary.x, &summary.objective)) summary.objective = nan;
  summary.constraint_violation = nlp->BoundViolation(summary.x);
  const RolloutStatistics after = nlp->set().statistics();
  summary.evaluations = after.rollouts - before.rollouts;
  summary.backward_passes =
      (after.adjoint_passes + after.tangent_passes) - (before.adjoint_passes + before.tangent_passes);
  summary.forward_seconds = after.forward_seconds - before.forward_seconds;
  summary.backward_seconds = after.backward_seconds - before.backward_seconds;
  const std::vector<double>& history = nlp->objective_history();
  summary.objective_history.assign(history.begin() + static_cast<long>(first_iteration), history.end());
  summary.iterations = std::max(0, static_cast<int>(summary.objective_history.size()) - 1);
  summary.log = journal->text();
  summary.derivative_checker_errors = ParseDerivativeCheck(summary.log);
  summary.last_error = nlp->last_error();
  summary.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace diffpd::solvers
