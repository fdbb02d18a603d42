#include "paper/paper_row.h"

#include <algorithm>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

void CheckSize(const VectorXd& x, int expected, const std::string& what) {
  if (x.size() != expected) {
    std::ostringstream msg;
    msg << what << " has " << x.size() << " entries, expected " << expected << " (one per variable)";
    throw InvalidInputError(msg.str());
  }
}

}  // namespace

int PaperRow::num_variables() const {
  int n = 0;
  for (const auto& block : variables) n += block->size();
  return n;
}

VectorXd PaperRow::lower() const {
  VectorXd out(num_variables());
  int offset = 0;
  for (const auto& block : variables) {
    out.segment(offset, block->size()) = block->lower();
    offset += block->size();
  }
  return out;
}

VectorXd PaperRow::upper() const {
  VectorXd out(num_variables());
  int offset = 0;
  for (const auto& block : variables) {
    out.segment(offset, block->size()) = block->upper();
    offset += block->size();
  }
  return out;
}

VectorXd PaperRow::initial_unprojected() const {
  VectorXd out(num_variables());
  int offset = 0;
  for (const auto& block : variables) {
    out.segment(offset, block->size()) = block->initial();
    offset += block->size();
  }
  return out;
}

VectorXd PaperRow::initial() const { return initial_unprojected().cwiseMax(lower()).cwiseMin(upper()); }

void PaperRow::SetInitial(const VectorXd& x) {
  CheckSize(x, num_variables(), name + ": x_init");
  int offset = 0;
  for (const auto& block : variables) {
    block->SetInitial(x.segment(offset, block->size()));
    offset += block->size();
  }
}

solvers::RolloutSetup PaperRow::Setup(const VectorXd& x) const {
  CheckSize(x, num_variables(), name + ": the variables");
  solvers::RolloutSetup setup = base;
  int offset = 0;
  for (const auto& block : variables) {
    block->Apply(x.segment(offset, block->size()), &setup);
    offset += block->size();
  }
  return setup;
}

VectorXd PaperRow::PullBack(const VectorXd& x, const RolloutGradient& gradient) const {
  CheckSize(x, num_variables(), name + ": the variables");
  VectorXd out(num_variables());
  int offset = 0;
  for (const auto& block : variables) {
    block->PullBack(x.segment(offset, block->size()), gradient, out.segment(offset, block->size()));
    offset += block->size();
  }
  return out;
}

double PaperRow::Loss(const Rollout& rollout, LossGradient* gradient) const {
  if (gradient) *gradient = LossGradient(rollout.num_steps());
  double value = 0;
  for (const LossTerm& term : loss) {
    value += term.weight * term.function->Value(rollout);
    if (gradient) term.function->AddGradient(rollout, term.weight, gradient);
  }
  return value;
}

SolverOptions PaperRow::Options(Method method, int threads) const {
  SolverOptions o;
  o.method = method;
  o.time_step = time_step;
  o.rel_tolerance = solver.rel_tolerance;
  o.abs_tolerance = solver.abs_tolerance;
  o.tolerance_reference = solver.tolerance_reference;
  o.backward_rel_tolerance = solver.rel_tolerance;
  o.max_iterations = solver.max_iterations;
  o.max_line_search_steps = solver.max_line_search_steps;
  o.lbfgs_history = solver.lbfgs_history;
  o.num_threads = threads;
  return o;
}

void PaperRow::Prepare(const SolverOptions& options) {
  if (!prepare) return;
  const auto run = std::move(prepare);
  prepare = nullptr;
  run(this, options);
}

namespace {
constexpr const char* kOriginalTestNote =
    "step tolerance: the original's test, |grad g| <= abs_tol + rel_tol |(M / h^2)(x_i + h v_i) + f| on the free "
    "DoFs (relative to the inertial term; this library's default is relative to the step's first residual, a far "
    "tighter test), with this library's masses M";
constexpr const char* kLumpedMassNote =
    "masses: lumped (each element's rho V shared by its 8 corners), where the original gives every node rho dx^3 "
    "(heavier surface nodes there, and more total mass)";
}  // namespace

void SetRowMasses(PaperRow* row, MassLumping masses) {
  row->scene.mass_lumping = masses;
  auto& notes = row->notes;
  notes.erase(std::remove(notes.begin(), notes.end(), std::string(kLumpedMassNote)), notes.end());
  if (masses == MassLumping::kLumped) notes.insert(notes.begin(), kLumpedMassNote);
}

std::vector<std::string> CommonRowNotes() {
  return {
      kLumpedMassNote,
      kOriginalTestNote,
      "pd-lbfgs: this library's preconditioner (the PD matrix with its elastic weights scaled by 0.3, and a coarse "
      "correction of the rigid modes of bodies without Dirichlet nodes) where DiffPD uses the PD matrix itself",
      "newton-pcg: CG with incomplete Cholesky stopped at relative residual 1e-8, where the original uses Eigen's "
      "default (machine precision)",
  };
}

void UseStartResidualTest(PaperRow* row, const std::string& why) {
  row->solver.tolerance_reference = ToleranceReference::kStartResidual;
  auto& notes = row->notes;
  notes.erase(std::remove(notes.begin(), notes.end(), std::string(kOriginalTestNote)), notes.end());
  notes.push_back(
      "step tolerance: this library's test for every method, |grad g| <= abs_tol + rel_tol |grad g(x_i + "
      "h v_i)| (relative to the step's first residual), where the original's test is relative to the "
      "inertial term: " +
      why);
}

std::string FrictionalContactNote() {
  return "contact: nodes stick where they touch, pinned at the projection of their start-of-step position on the "
         "plane (the original: at the start-of-step position), released when the contact force pulls; up to 20 "
         "active-set passes per step (the original: 5)";
}

}  // namespace diffpd::problems
