#include "diffpd/solvers/core/rollout_function.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

bool SameMaterial(const MaterialParameters& a, const MaterialParameters& b) {
  return a.youngs_modulus == b.youngs_modulus && a.poissons_ratio == b.poissons_ratio && a.density == b.density;
}

// Activations of 1 (rest) where a scene with muscles has none, so that
// activation blocks can set single entries and directions know the size.
void FillRestActivations(int muscles, std::vector<StepInput>* inputs) {
  if (muscles == 0) return;
  for (StepInput& in : *inputs)
    if (in.activation.size() == 0) in.activation = VectorXd::Ones(muscles);
}

// The last state with a non-empty entry in `loss` (0 if none).
int LastNonEmpty(const LossGradient& loss) {
  for (int k = static_cast<int>(loss.dx.size()) - 1; k > 0; --k)
    if (loss.dx[k].size() || (k < static_cast<int>(loss.dv.size()) && loss.dv[k].size())) return k;
  return 0;
}

bool IsEmpty(const LossGradient& loss) {
  for (const VectorXd& v : loss.dx)
    if (v.size()) return false;
  for (const VectorXd& v : loss.dv)
    if (v.size()) return false;
  return true;
}

}  // namespace

const char* ToString(DerivativeMode mode) {
  switch (mode) {
    case DerivativeMode::kAuto:
      return "auto";
    case DerivativeMode::kForward:
      return "forward";
    case DerivativeMode::kReverse:
      return "reverse";
  }
  return "unknown";
}

struct RolloutFunction::Cache {
  VectorXd point;
  bool valid = false;  // point holds an evaluated point
  bool ok = false;     // its rollout and values succeeded
  RolloutSetup setup;
  Rollout rollout;
  VectorXd values;             // M
  MatrixXd jacobian;           // M x N; rows where have_row
  std::vector<char> have_row;  // M
  bool jacobian_failed = false;
  bool have_gradient = false, gradient_ok = false;
  VectorXd gradient_weights, gradient;
};

RolloutFunction::RolloutFunction(const Scene& scene, const SolverOptions& options, int num_steps)
    : scene_(scene), options_(options), cache_(std::make_unique<Cache>()) {
  if (num_steps < 1) {
    std::ostringstream msg;
    msg << "RolloutFunction: num_steps = " << num_steps << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
  sim_ = std::make_unique<Simulator>(scene_, options_);
  sim_state_forces_ = StateForceParameters::Of(scene_);
  base_.initial = sim_->RestState();
  base_.inputs.resize(num_steps);
  FillRestActivations(static_cast<int>(scene_.muscles.size()), &base_.inputs);
  base_.material = scene_.material;
  for (const MaterialRegion& r : scene_.material_regions) base_.region_materials.push_back(r.material);
  base_.state_forces = sim_state_forces_;
}

RolloutFunction::~RolloutFunction() = default;

void RolloutFunction::Invalidate() { cache_ = std::make_unique<Cache>(); }

void RolloutFunction::SetInitialState(const State& initial) {
  const Eigen::Index n = sim_->num_dofs();
  if (initial.x.size() != n || initial.v.size() != n) {
    std::ostringstream msg;
    msg << "initial state has " << initial.x.size() << " positions and " << initial.v.size() << " velocities, expected "
        << n << " each";
    throw InvalidInputError(msg.str());
  }
  if (!initial.x.allFinite() || !initial.v.allFinite()) throw InvalidInputError("initial state has a non-finite entry");
  base_.initial = initial;
  Invalidate();
}

void RolloutFunction::SetInputs(std::vector<StepInput> inputs) {
  if (inputs.size() != base_.inputs.size()) {
    std::ostringstream msg;
    msg << "inputs has " << inputs.size() << " steps, expected " << base_.inputs.size();
    throw InvalidInputError(msg.str());
  }
  FillRestActivations(static_cast<int>(scene_.muscles.size()), &inputs);
  base_.inputs = std::move(inputs);
  Invalidate();
}

int RolloutFunction::AddBlock(std::unique_ptr<ParameterBlock> block) {
  if (!block) throw InvalidInputError("RolloutFunction: the parameter block is null");
  block->CheckFits(scene_, num_steps());
  const int offset = num_parameters_;
  num_parameters_ += block->size();
  block_of_.insert(block_of_.end(), block->size(), static_cast<int>(blocks_.size()));
  blocks_.push_back(Block{std::move(block), offset});
  Invalidate();
  return offset;
}

VectorXd RolloutFunction::initial_parameters() const {
  VectorXd p(num_parameters_);
  for (const Block& b : blocks_) p.segment(b.offset, b.block->size()) = b.block->initial();
  return p;
}

VectorXd RolloutFunction::lower_bounds() const {
  VectorXd p(num_parameters_);
  for (const Block& b : blocks_) p.segment(b.offset, b.block->size()) = b.block->lower();
  return p;
}

VectorXd RolloutFunction::upper_bounds() const {
  VectorXd p(num_parameters_);
  for (const Block& b : blocks_) p.segment(b.offset, b.block->size()) = b.block->upper();
  return p;
}

RolloutSetup RolloutFunction::SetupAt(const Eigen::Ref<const VectorXd>& p) const {
  if (p.size() != num_parameters_) {
    std::ostringstream msg;
    msg << "the parameter vector has " << p.size() << " entries, expected " << num_parameters_;
    throw InvalidInputError(msg.str());
  }
  RolloutSetup setup = base_;
  for (const Block& b : blocks_) b.block->Apply(p.segment(b.offset, b.block->size()), &setup);
  return setup;
}

int RolloutFunction::FirstAffectedState(int j) const {
  const Block& b = blocks_[block_of_[j]];
  return b.block->FirstAffectedState(j - b.offset);
}

int RolloutFunction::AddFunctional(std::unique_ptr<TrajectoryFunctional> functional) {
  if (!functional) throw InvalidInputError("RolloutFunction: the functional is null");
  const int m = functional->num_values();
  if (m < 1) throw InvalidInputError("functional '" + functional->name() + "' has no value");
  const int K = num_steps();
  for (int i = 0; i < m; ++i) {
    const int last = functional->LastStateOf(i, K);
    if (last < 0 || last > K) {
      std::ostringstream msg;
      msg << "functional '" << functional->name() << "' reads state " << last << ", outside the rollout's states [0, "
          << K << "]";
      throw InvalidInputError(msg.str());
    }
  }
  functionals_.push_back(Functional{std::move(functional), num_rows_});
  num_rows_ += m;
  Invalidate();
  return num_functionals() - 1;
}

std::vector<int> RolloutFunction::RowsOf(int i) const {
  std::vector<int> rows(functionals_[i].functional->num_values());
  for (size_t r = 0; r < rows.size(); ++r) rows[r] = functionals_[i].row + static_cast<int>(r);
  return rows;
}

std::vector<int> RolloutFunction::AllRows() const {
  std::vector<int> rows(num_rows_);
  for (int r = 0; r < num_rows_; ++r) rows[r] = r;
  return rows;
}

int RolloutFunction::FunctionalOf(int row) const {
  int f = 0;
  while (f + 1 < num_functionals() && functionals_[f + 1].row <= row) ++f;
  return f;
}

int RolloutFunction::LastState(int row) const {
  const Functional& f = functionals_[FunctionalOf(row)];
  return f.functional->LastStateOf(row - f.row, num_steps());
}

void RolloutFunction::SetDerivativeMode(DerivativeMode mode) {
  mode_ = mode;
  std::fill(cache_->have_row.begin(), cache_->have_row.end(), 0);
  cache_->jacobian_failed = false;
}

bool RolloutFunction::ForwardModeAvailable() const {
  for (const Block& b : blocks_)
    if (!b.block->SupportsForwardMode()) return false;
  return true;
}

DerivativeMode RolloutFunction::ResolvedMode(int num_rows) const {
  if (mode_ != DerivativeMode::kAuto) return mode_;
  return ForwardModeAvailable() && num_parameters_ < num_rows ? DerivativeMode::kForward : DerivativeMode::kReverse;
}

// ---- evaluation ---------------------------------------------------------------

void RolloutFunction::Fail(const std::string& stage, const std::exception_ptr& error) {
  std::string message;
  try {
    std::rethrow_exception(error);
  } catch (const SolverError& e) {
    message = stage + " failed (" + ToString(e.status()) + "): " + e.what();
  } catch (const InvalidInputError& e) {
    message = stage + " rejected: " + e.what();
  } catch (const std::exception& e) {
    message = stage + " error: " + e.what();
  } catch (...) {
    message = stage + " error: unknown exception";
  }
  ++stats_.failures;
  stats_.last_error = message;
}

void RolloutFunction::PrepareSimulator(const RolloutSetup& setup) {
  if (setup.state_forces != sim_state_forces_) {
    Scene scene = scene_;
    setup.state_forces.ApplyTo(&scene);
    sim_ = std::make_unique<Simulator>(scene, options_);
    sim_state_forces_ = setup.state_forces;
  }
  if (!SameMaterial(setup.material, sim_->scene().material)) sim_->SetMaterial(setup.material);
  for (size_t r = 0; r < setup.region_materials.size(); ++r)
    if (!SameMaterial(setup.region_materials[r], sim_->scene().material_regions[r].material))
      sim_->SetRegionMaterial(static_cast<int>(r), setup.region_materials[r]);
}

bool RolloutFunction::Evaluate(const Eigen::Ref<const VectorXd>& p) {
  std::lock_guard<std::mutex> lock(mutex_);
  return EvaluateLocked(p);
}

bool RolloutFunction::EvaluateLocked(const Eigen::Ref<const VectorXd>& p) {
  Cache& c = *cache_;
  if (c.valid && c.point.size() == p.size() && c.point == p) return c.ok;
  c = Cache();
  c.point = p;
  c.valid = true;
  ++stats_.rollouts;
  const auto start = Clock::now();
  try {
    for (Eigen::Index j = 0; j < p.size(); ++j)
      if (!std::isfinite(p(j))) {
        std::ostringstream msg;
        msg << "parameter " << j << " = " << p(j) << " is not finite";
        throw InvalidInputError(msg.str());
      }
    c.setup = SetupAt(p);
    PrepareSimulator(c.setup);
    c.rollout = c.setup.controller ? sim_->Simulate(c.setup.initial, *c.setup.controller, num_steps())
                                   : sim_->Simulate(c.setup.initial, c.setup.inputs);
  } catch (...) {
    stats_.forward_seconds += Seconds(start);
    ++stats_.failed_rollouts;
    Fail("rollout", std::current_exception());
    return false;
  }
  stats_.forward_seconds += Seconds(start);
  try {
    c.values.resize(num_rows_);
    for (const Functional& f : functionals_) {
      const int m = f.functional->num_values();
      f.functional->Evaluate(c.rollout, c.values.segment(f.row, m));
      for (int i = 0; i < m; ++i)
        if (!std::isfinite(c.values(f.row + i))) {
          std::ostringstream msg;
          msg << "functional '" << f.functional->name() << "' value " << i << " = " << c.values(f.row + i)
              << " is not finite";
          throw InvalidInputError(msg.str());
        }
    }
  } catch (...) {
    ++stats_.failed_rollouts;
    Fail("values", std::current_exception());
    return false;
  }
  c.jacobian.resize(num_rows_, num_parameters_);
  c.have_row.assign(num_rows_, 0);
  c.ok = true;
  return true;
}

bool RolloutFunction::Evaluate(const Eigen::Ref<const VectorXd>& p, const std::vector<int>& rows, VectorXd* values,
                               MatrixXd* jacobian) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!EvaluateLocked(p)) return false;
  Cache& c = *cache_;
  for (int r : rows)
    if (r < 0 || r >= num_rows_) {
      std::ostringstream msg;
      msg << "values rejected: row " << r << " is out of range [0, " << num_rows_ << ")";
      ++stats_.failures;
      stats_.last_error = msg.str();
      return false;
    }
  if (values) {
    values->resize(rows.size());
    for (size_t i = 0; i < rows.size(); ++i) (*values)(i) = c.values(rows[i]);
  }
  if (!jacobian) return true;
  std::vector<int> missing;
  for (int r : rows)
    if (!c.have_row[r] && std::find(missing.begin(), missing.end(), r) == missing.end()) missing.push_back(r);
  if (!missing.empty()) {
    if (c.jacobian_failed) return false;
    try {
      ComputeRows(missing);
    } catch (...) {
      c.jacobian_failed = true;
      Fail("Jacobian", std::current_exception());
      return false;
    }
  }
  jacobian->resize(rows.size(), num_parameters_);
  for (size_t i = 0; i < rows.size(); ++i) jacobian->row(i) = c.jacobian.row(rows[i]);
  return true;
}

void RolloutFunction::ComputeRows(const std::vector<int>& missing) {
  Cache& c = *cache_;
  if (num_parameters_ == 0) {
    for (int r : missing) c.have_row[r] = 1;
    return;
  }
  if (ResolvedMode(static_cast<int>(missing.size())) == DerivativeMode::kForward) {
    if (!ForwardModeAvailable())
      throw InvalidInputError(
          "forward mode does not cover this rollout (a parameter block without forward mode); use "
          "DerivativeMode::kReverse or kAuto");
    ForwardRows(missing);
  } else {
    ReverseRows(missing);
  }
  ++stats_.jacobians;
  for (int r : missing) {
    Eigen::Index j = 0;
    while (j < c.jacobian.cols() && std::isfinite(c.jacobian(r, j))) ++j;
    if (j == c.jacobian.cols()) continue;
    for (int m : missing) c.have_row[m] = 0;  // never served from the cache
    const Functional& f = functionals_[FunctionalOf(r)];
    std::ostringstream msg;
    msg << "row " << r << " (functional '" << f.functional->name() << "' value " << r - f.row
        << "): the derivative with respect to parameter " << j << " = " << c.jacobian(r, j) << " is not finite";
    throw SolverError(SolverStatus::kNonFinite, msg.str());
  }
}

void RolloutFunction::ForwardRows(const std::vector<int>& missing) {
  Cache& c = *cache_;
  const int K = num_steps(), n = sim_->num_dofs();
  const int regions = static_cast<int>(scene_.material_regions.size());
  std::vector<InputDirection> directions(num_parameters_);
  for (const Block& b : blocks_) {
    const Eigen::Ref<const VectorXd> values = c.point.segment(b.offset, b.block->size());
    for (int j = 0; j < b.block->size(); ++j) {
      InputDirection& d = directions[b.offset + j];
      d.x0 = VectorXd::Zero(n);
      d.v0 = VectorXd::Zero(n);
      d.external_force.assign(K, VectorXd());
      d.activation.assign(K, VectorXd());
      if (regions > 0) d.region_materials.assign(regions, MaterialComponents());
      b.block->PushForward(values, j, c.setup, &d);
    }
  }
  const auto start = Clock::now();
  TangentRollout tangents;
  try {
    tangents = sim_->Tangents(c.rollout, directions);
  } catch (...) {
    stats_.backward_seconds += Seconds(start);
    ++stats_.tangent_passes;
    throw;
  }
  stats_.backward_seconds += Seconds(start);
  ++stats_.tangent_passes;
  std::vector<char> done(num_functionals(), 0);
  for (int r : missing) {
    const int fi = FunctionalOf(r);
    if (done[fi]) continue;
    done[fi] = 1;
    const Functional& f = functionals_[fi];
    const int m = f.functional->num_values();
    f.functional->ApplyTangents(c.rollout, tangents, c.jacobian.middleRows(f.row, m));
    std::fill(c.have_row.begin() + f.row, c.have_row.begin() + f.row + m, 1);
  }
}

void RolloutFunction::ReverseRows(const std::vector<int>& missing) {
  Cache& c = *cache_;
  const int K = num_steps();
  // Rows in order of their last state: one truncated rollout per last state.
  std::vector<std::pair<int, int>> order;  // (last state, row)
  for (int r : missing) order.emplace_back(LastState(r), r);
  std::stable_sort(order.begin(), order.end(),
                   [](const std::pair<int, int>& a, const std::pair<int, int>& b) { return a.first < b.first; });
  Rollout part;
  int part_steps = -1;
  for (const auto& [declared_last, r] : order) {
    const Functional& f = functionals_[FunctionalOf(r)];
    VectorXd unit = VectorXd::Zero(f.functional->num_values());
    unit(r - f.row) = 1;
    LossGradient loss(K);
    f.functional->AddWeightedGradient(c.rollout, unit, &loss);
    if (IsEmpty(loss)) {
      c.jacobian.row(r).setZero();
      c.have_row[r] = 1;
      continue;
    }
    const int last = std::max(declared_last, LastNonEmpty(loss));
    if (last < K && last != part_steps) {
      part = c.rollout.Truncated(last);
      part_steps = last;
    }
    c.jacobian.row(r) = PullBack(last < K ? part : c.rollout, loss, last).transpose();
    c.have_row[r] = 1;
  }
}

VectorXd RolloutFunction::PullBack(const Rollout& rollout, LossGradient loss, int last) {
  Cache& c = *cache_;
  loss.dx.resize(last + 1);
  loss.dv.resize(last + 1);
  const auto start = Clock::now();
  RolloutGradient grad;
  try {
    grad = c.setup.controller ? sim_->Backward(rollout, loss, *c.setup.controller) : sim_->Backward(rollout, loss);
  } catch (...) {
    stats_.backward_seconds += Seconds(start);
    ++stats_.adjoint_passes;
    throw;
  }
  stats_.backward_seconds += Seconds(start);
  ++stats_.adjoint_passes;
  VectorXd out(num_parameters_);
  for (const Block& b : blocks_)
    b.block->PullBack(c.point.segment(b.offset, b.block->size()), grad, out.segment(b.offset, b.block->size()));
  return out;
}

bool RolloutFunction::Gradient(const Eigen::Ref<const VectorXd>& p, const Eigen::Ref<const VectorXd>& weights,
                               VectorXd* gradient, double* value) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!EvaluateLocked(p)) return false;
  Cache& c = *cache_;
  if (weights.size() != num_rows_) {
    std::ostringstream msg;
    msg << "gradient rejected: the weights have " << weights.size() << " entries, expected " << num_rows_;
    ++stats_.failures;
    stats_.last_error = msg.str();
    return false;
  }
  if (value) *value = weights.dot(c.values);
  if (!(c.have_gradient && c.gradient_weights == weights)) {
    c.have_gradient = true;
    c.gradient_weights = weights;
    c.gradient_ok = false;
    try {
      const int K = num_steps();
      LossGradient loss(K);
      int last = -1;
      for (const Functional& f : functionals_) {
        const int m = f.functional->num_values();
        const auto slice = weights.segment(f.row, m);
        if (slice.isZero(0)) continue;
        f.functional->AddWeightedGradient(c.rollout, slice, &loss);
        for (int i = 0; i < m; ++i)
          if (slice(i) != 0) last = std::max(last, f.functional->LastStateOf(i, K));
      }
      if (last < 0 || IsEmpty(loss)) {
        c.gradient = VectorXd::Zero(num_parameters_);
      } else {
        last = std::max(last, LastNonEmpty(loss));
        c.gradient = last < K ? PullBack(c.rollout.Truncated(last), loss, last) : PullBack(c.rollout, loss, last);
      }
      for (Eigen::Index j = 0; j < c.gradient.size(); ++j)
        if (!std::isfinite(c.gradient(j))) {
          std::ostringstream msg;
          msg << "the derivative with respect to parameter " << j << " = " << c.gradient(j) << " is not finite";
          throw SolverError(SolverStatus::kNonFinite, msg.str());
        }
      ++stats_.gradients;
      c.gradient_ok = true;
    } catch (...) {
      Fail("gradient", std::current_exception());
    }
  }
  if (!c.gradient_ok) return false;
  *gradient = c.gradient;
  return true;
}

const Rollout* RolloutFunction::RolloutAt(const Eigen::Ref<const VectorXd>& p) {
  std::lock_guard<std::mutex> lock(mutex_);
  return EvaluateLocked(p) ? &cache_->rollout : nullptr;
}

}  // namespace diffpd::solvers
