#include "diffpd/solvers/calibration_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

int StepsFor(const CalibrationSetup& setup) {
  if (setup.num_steps < 0)
    throw InvalidInputError("num_steps = " + std::to_string(setup.num_steps) +
                            " is invalid: must be >= 0 (0: enough to reach the last sample)");
  setup.solver.Validate();
  setup.motion.Validate();
  return setup.num_steps > 0 ? setup.num_steps
                             : MarkerObservations::RequiredSteps(setup.motion, setup.solver.time_step);
}

void CheckBasis(const MatrixXd& basis, const char* name, int* columns) {
  if (basis.size() == 0) return;
  if (basis.rows() % 3 != 0) {
    std::ostringstream msg;
    msg << name << " has " << basis.rows() << " rows, expected 3 x number of nodes";
    throw InvalidInputError(msg.str());
  }
  if (!basis.allFinite()) throw InvalidInputError(std::string(name) + " has a non-finite entry");
  if (*columns >= 0 && basis.cols() != *columns) {
    std::ostringstream msg;
    msg << name << " has " << basis.cols() << " columns, but another basis has " << *columns;
    throw InvalidInputError(msg.str());
  }
  *columns = static_cast<int>(basis.cols());
}

double& Field(MaterialParameters* m, MaterialParameter p) {
  switch (p) {
    case MaterialParameter::kYoungsModulus:
      return m->youngs_modulus;
    case MaterialParameter::kPoissonsRatio:
      return m->poissons_ratio;
    case MaterialParameter::kDensity:
      return m->density;
  }
  DIFFPD_CHECK(false, "unknown MaterialParameter " << static_cast<int>(p));
}

double Field(const MaterialComponents& c, MaterialParameter p) {
  switch (p) {
    case MaterialParameter::kYoungsModulus:
      return c.youngs_modulus;
    case MaterialParameter::kPoissonsRatio:
      return c.poissons_ratio;
    case MaterialParameter::kDensity:
      return c.density;
  }
  DIFFPD_CHECK(false, "unknown MaterialParameter " << static_cast<int>(p));
}

}  // namespace

const char* ToString(MaterialParameter parameter) {
  switch (parameter) {
    case MaterialParameter::kYoungsModulus:
      return "youngs_modulus";
    case MaterialParameter::kPoissonsRatio:
      return "poissons_ratio";
    case MaterialParameter::kDensity:
      return "density";
  }
  return "unknown";
}

LinearInputParameters::LinearInputParameters(MatrixXd position_basis, MatrixXd velocity_basis, MatrixXd force_basis,
                                             int force_begin, int force_end)
    : position_(std::move(position_basis)),
      velocity_(std::move(velocity_basis)),
      force_(std::move(force_basis)),
      force_begin_(force_begin),
      force_end_(force_end) {
  int columns = -1;
  CheckBasis(position_, "position_basis", &columns);
  CheckBasis(velocity_, "velocity_basis", &columns);
  CheckBasis(force_, "force_basis", &columns);
  if (columns <= 0) throw InvalidInputError("LinearInputParameters: no basis with at least one column given");
  if (force_begin_ < 0 || force_end_ < force_begin_) {
    std::ostringstream msg;
    msg << "force_begin = " << force_begin_ << ", force_end = " << force_end_ << " is invalid: need 0 <= begin <= end";
    throw InvalidInputError(msg.str());
  }
  size_ = columns;
}

LinearInputParameters LinearInputParameters::UniformInitialVelocity(int num_nodes) {
  MatrixXd basis = MatrixXd::Zero(3 * num_nodes, 3);
  for (int i = 0; i < num_nodes; ++i) basis.block<3, 3>(3 * i, 0).setIdentity();
  return LinearInputParameters(MatrixXd(), basis);
}

void LinearInputParameters::Apply(const double* p, State* initial, std::vector<StepInput>* inputs,
                                  std::vector<InputDirection>* directions) const {
  const Eigen::Map<const VectorXd> q(p, size_);
  const Eigen::Index n = initial->x.size();
  for (const MatrixXd* b : {&position_, &velocity_, &force_})
    if (b->size() && b->rows() != n) {
      std::ostringstream msg;
      msg << "LinearInputParameters: a basis has " << b->rows() << " rows but the scene has " << n << " DoFs";
      throw InvalidInputError(msg.str());
    }
  const int steps = static_cast<int>(inputs->size());
  const int end = std::min(force_end_, steps);
  if (position_.size()) initial->x += position_ * q;
  if (velocity_.size()) initial->v += velocity_ * q;
  if (force_.size()) {
    const VectorXd f = force_ * q;
    for (int k = force_begin_; k < end; ++k) {
      VectorXd& fk = (*inputs)[k].external_force;
      if (fk.size() == 0) fk = VectorXd::Zero(n);
      fk += f;
    }
  }
  if (!directions) return;
  directions->assign(size_, InputDirection());
  for (int j = 0; j < size_; ++j) {
    InputDirection& d = (*directions)[j];
    if (position_.size()) d.x0 = position_.col(j);
    if (velocity_.size()) d.v0 = velocity_.col(j);
    if (force_.size() && end > force_begin_) {
      d.external_force.assign(steps, VectorXd());
      for (int k = force_begin_; k < end; ++k) d.external_force[k] = force_.col(j);
    }
  }
}

CalibrationModel::CalibrationModel(CalibrationSetup setup)
    : setup_(std::move(setup)),
      sim_(std::make_unique<Simulator>(setup_.scene, setup_.solver)),
      observations_(setup_.motion, setup_.scene.mesh, setup_.solver.time_step, StepsFor(setup_)),
      num_steps_(observations_.num_steps()) {
  const int n = sim_->num_dofs();
  std::set<MaterialParameter> seen;
  for (MaterialParameter p : setup_.fitted)
    if (!seen.insert(p).second) throw InvalidInputError(std::string("fitted lists ") + ToString(p) + " twice");
  const int regions = static_cast<int>(setup_.scene.material_regions.size());
  std::set<std::pair<int, MaterialParameter>> seen_regions;
  for (size_t i = 0; i < setup_.fitted_regions.size(); ++i) {
    const RegionParameter& rp = setup_.fitted_regions[i];
    if (rp.region < 0 || rp.region >= regions) {
      std::ostringstream msg;
      msg << "fitted_regions[" << i << "]: region " << rp.region << " is out of range [0, " << regions << ")";
      throw InvalidInputError(msg.str());
    }
    if (!seen_regions.insert({rp.region, rp.parameter}).second) {
      std::ostringstream msg;
      msg << "fitted_regions lists " << ToString(rp.parameter) << " of region " << rp.region << " twice";
      throw InvalidInputError(msg.str());
    }
  }
  const int material_size = static_cast<int>(setup_.fitted.size() + setup_.fitted_regions.size());
  if (material_size > 0) {
    material_block_ = static_cast<int>(block_sizes_.size());
    block_sizes_.push_back(material_size);
  }
  if (setup_.input_parameters) {
    if (setup_.input_parameters->size() < 1) throw InvalidInputError("input_parameters has no parameter");
    input_block_ = static_cast<int>(block_sizes_.size());
    block_sizes_.push_back(setup_.input_parameters->size());
  }
  if (block_sizes_.empty())
    throw InvalidInputError(
        "nothing to fit: `fitted` and `fitted_regions` are empty and there are no input_parameters");
  for (int s : block_sizes_) num_parameters_ += s;
  if (setup_.initial) {
    if (setup_.initial->x.size() != n || setup_.initial->v.size() != n) {
      std::ostringstream msg;
      msg << "initial state has " << setup_.initial->x.size() << " positions and " << setup_.initial->v.size()
          << " velocities, expected " << n << " each";
      throw InvalidInputError(msg.str());
    }
  } else {
    setup_.initial = sim_->RestState();
  }
  if (setup_.inputs.empty()) setup_.inputs.resize(num_steps_);
  if (static_cast<int>(setup_.inputs.size()) != num_steps_) {
    std::ostringstream msg;
    msg << "inputs has " << setup_.inputs.size() << " steps, expected " << num_steps_;
    throw InvalidInputError(msg.str());
  }
  jacobians_.resize(block_sizes_.size());
}

void CalibrationModel::InitialMaterialBlock(double* block) const {
  MaterialParameters base = setup_.scene.material;
  const size_t nb = setup_.fitted.size();
  for (size_t i = 0; i < nb; ++i) block[i] = Field(&base, setup_.fitted[i]);
  for (size_t i = 0; i < setup_.fitted_regions.size(); ++i) {
    const RegionParameter& rp = setup_.fitted_regions[i];
    MaterialParameters m = setup_.scene.material_regions[rp.region].material;
    block[nb + i] = Field(&m, rp.parameter);
  }
}

MaterialParameters CalibrationModel::MaterialAt(const double* block) const {
  MaterialParameters m = setup_.scene.material;
  for (size_t i = 0; i < setup_.fitted.size(); ++i) Field(&m, setup_.fitted[i]) = block[i];
  return m;
}

MaterialParameters CalibrationModel::RegionMaterialAt(const double* block, int region) const {
  const int regions = static_cast<int>(setup_.scene.material_regions.size());
  if (region < 0 || region >= regions) {
    std::ostringstream msg;
    msg << "RegionMaterialAt: region " << region << " is out of range [0, " << regions << ")";
    throw InvalidInputError(msg.str());
  }
  MaterialParameters m = setup_.scene.material_regions[region].material;
  const size_t nb = setup_.fitted.size();
  for (size_t i = 0; i < setup_.fitted_regions.size(); ++i)
    if (setup_.fitted_regions[i].region == region) Field(&m, setup_.fitted_regions[i].parameter) = block[nb + i];
  return m;
}

std::vector<std::vector<int>> CalibrationModel::SamplesByFrame() const {
  std::map<double, std::vector<int>> frames;
  for (int s = 0; s < observations_.num_samples(); ++s) frames[observations_.time(s)].push_back(s);
  std::vector<std::vector<int>> out;
  for (auto& kv : frames) out.push_back(std::move(kv.second));
  return out;
}

void CalibrationModel::Fail(const std::string& message) {
  ++stats_.failures;
  stats_.last_error = message;
}

bool CalibrationModel::Prepare(const double* const* parameters) {
  std::vector<double> point;
  point.reserve(num_parameters_);
  for (size_t b = 0; b < block_sizes_.size(); ++b)
    point.insert(point.end(), parameters[b], parameters[b] + block_sizes_[b]);
  if (have_point_ && point == point_) return point_ok_;
  have_point_ = true;
  point_ok_ = false;
  have_jacobian_ = false;
  point_ = point;
  const auto start = Clock::now();
  try {
    for (double v : point)
      if (!std::isfinite(v)) throw InvalidInputError("a parameter is not finite");
    if (material_block_ >= 0) {
      sim_->SetMaterial(MaterialAt(parameters[material_block_]));
      for (const RegionParameter& rp : setup_.fitted_regions)
        sim_->SetRegionMaterial(rp.region, RegionMaterialAt(parameters[material_block_], rp.region));
    }
    State initial = *setup_.initial;
    std::vector<StepInput> inputs = setup_.inputs;
    input_directions_.clear();
    if (input_block_ >= 0)
      setup_.input_parameters->Apply(parameters[input_block_], &initial, &inputs, &input_directions_);
    rollout_ = sim_->Simulate(initial, inputs);
    residuals_ = observations_.Residuals(rollout_.states);
    point_ok_ = true;
  } catch (const SolverError& e) {
    Fail(std::string("rollout failed (") + ToString(e.status()) + "): " + e.what());
  } catch (const InvalidInputError& e) {
    Fail(std::string("rollout rejected: ") + e.what());
  } catch (const std::exception& e) {
    Fail(std::string("rollout error: ") + e.what());
  }
  ++stats_.rollouts;
  stats_.forward_seconds += Seconds(start);
  return point_ok_;
}

bool CalibrationModel::Evaluate(const double* const* parameters, bool jacobian) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!Prepare(parameters)) return false;
  if (!jacobian) return true;
  if (have_jacobian_) return jacobian_ok_;
  return ComputeJacobian();
}

bool CalibrationModel::ComputeJacobian() {
  have_jacobian_ = true;
  jacobian_ok_ = false;
  const auto start = Clock::now();
  try {
    if (setup_.jacobian == JacobianMode::kForward)
      ForwardJacobian();
    else
      ReverseJacobian();
    jacobian_ok_ = true;
  } catch (const SolverError& e) {
    Fail(std::string("derivative failed (") + ToString(e.status()) + "): " + e.what());
  } catch (const InvalidInputError& e) {
    Fail(std::string("derivative rejected: ") + e.what());
  } catch (const std::exception& e) {
    Fail(std::string("derivative error: ") + e.what());
  }
  ++stats_.jacobians;
  stats_.backward_seconds += Seconds(start);
  return jacobian_ok_;
}

void CalibrationModel::ForwardJacobian() {
  std::vector<InputDirection> dirs;
  for (MaterialParameter p : setup_.fitted) {
    switch (p) {
      case MaterialParameter::kYoungsModulus:
        dirs.push_back(InputDirection::YoungsModulus());
        break;
      case MaterialParameter::kPoissonsRatio:
        dirs.push_back(InputDirection::PoissonsRatio());
        break;
      case MaterialParameter::kDensity:
        dirs.push_back(InputDirection::Density());
        break;
    }
  }
  const int regions = static_cast<int>(setup_.scene.material_regions.size());
  for (const RegionParameter& rp : setup_.fitted_regions) {
    switch (rp.parameter) {
      case MaterialParameter::kYoungsModulus:
        dirs.push_back(InputDirection::RegionYoungsModulus(rp.region, regions));
        break;
      case MaterialParameter::kPoissonsRatio:
        dirs.push_back(InputDirection::RegionPoissonsRatio(rp.region, regions));
        break;
      case MaterialParameter::kDensity:
        dirs.push_back(InputDirection::RegionDensity(rp.region, regions));
        break;
    }
  }
  dirs.insert(dirs.end(), input_directions_.begin(), input_directions_.end());
  const TangentRollout t = sim_->Tangents(rollout_, dirs);
  MatrixXd j = MatrixXd::Zero(num_residuals(), num_parameters_);
  for (int s = 0; s < observations_.num_samples(); ++s)
    for (const MarkerObservations::Term& term : observations_.terms(s))
      j.middleRows<3>(3 * s) += term.weight * t.dx[term.step].middleRows<3>(3 * term.node);
  for (int s = 0; s < observations_.num_samples(); ++s)
    j.middleRows<3>(3 * s) = observations_.weight(s).asDiagonal() * j.middleRows<3>(3 * s);
  int column = 0;
  for (size_t b = 0; b < block_sizes_.size(); ++b) {
    jacobians_[b] = j.middleCols(column, block_sizes_[b]);
    column += block_sizes_[b];
  }
}

VectorXd CalibrationModel::ParameterGradient(const RolloutGradient& g, int last_step) const {
  VectorXd out(num_parameters_);
  int column = 0;
  MaterialComponents base;
  base.youngs_modulus = g.youngs_modulus;
  base.poissons_ratio = g.poissons_ratio;
  base.density = g.density;
  for (MaterialParameter p : setup_.fitted) out(column++) = Field(base, p);
  for (const RegionParameter& rp : setup_.fitted_regions)
    out(column++) = Field(g.region_materials[rp.region], rp.parameter);
  for (const InputDirection& d : input_directions_) {
    double v = 0;
    if (d.x0.size()) v += g.x0.dot(d.x0);
    if (d.v0.size()) v += g.v0.dot(d.v0);
    for (int k = 0; k < last_step && k < static_cast<int>(d.external_force.size()); ++k)
      if (d.external_force[k].size()) v += g.external_force[k].dot(d.external_force[k]);
    for (int k = 0; k < last_step && k < static_cast<int>(d.activation.size()); ++k)
      if (d.activation[k].size() && g.activation[k].size()) v += g.activation[k].dot(d.activation[k]);
    out(column++) = v;
  }
  return out;
}

void CalibrationModel::ReverseJacobian() {
  MatrixXd j = MatrixXd::Zero(num_residuals(), num_parameters_);
  for (int s = 0; s < observations_.num_samples(); ++s) {
    const int last = observations_.last_step(s);
    // The rollout truncated after the last step this sample depends on.
    Rollout part;
    part.states.assign(rollout_.states.begin(), rollout_.states.begin() + last + 1);
    part.inputs.assign(rollout_.inputs.begin(), rollout_.inputs.begin() + last);
    part.reports.assign(rollout_.reports.begin(), rollout_.reports.begin() + last);
    part.material = rollout_.material;
    part.region_materials = rollout_.region_materials;
    part.options = rollout_.options;
    for (int d = 0; d < 3; ++d) {
      const double w = observations_.weight(s)(d);
      if (w == 0) continue;
      LossGradient loss(last);
      for (const MarkerObservations::Term& term : observations_.terms(s)) {
        VectorXd& dx = loss.dx[term.step];
        if (dx.size() == 0) dx = VectorXd::Zero(sim_->num_dofs());
        dx(3 * term.node + d) += w * term.weight;
      }
      j.row(3 * s + d) = ParameterGradient(sim_->Backward(part, loss), last).transpose();
    }
  }
  int column = 0;
  for (size_t b = 0; b < block_sizes_.size(); ++b) {
    jacobians_[b] = j.middleCols(column, block_sizes_[b]);
    column += block_sizes_[b];
  }
}

bool CalibrationModel::EvaluateLoss(const double* const* parameters, const TrajectoryLoss& loss, double* cost,
                                    double* gradient) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!Prepare(parameters)) return false;
  const auto start = Clock::now();
  bool ok = false;
  try {
    LossGradient dl(num_steps_);
    double value = 0;
    if (loss) {
      value = loss(rollout_, &dl);
    } else {
      value = 0.5 * residuals_.squaredNorm();
      for (int s = 0; s < observations_.num_samples(); ++s)
        for (const MarkerObservations::Term& term : observations_.terms(s)) {
          VectorXd& dx = dl.dx[term.step];
          if (dx.size() == 0) dx = VectorXd::Zero(sim_->num_dofs());
          dx.segment<3>(3 * term.node) +=
              term.weight * observations_.weight(s).cwiseProduct(residuals_.segment<3>(3 * s));
        }
    }
    if (!std::isfinite(value)) throw SolverError(SolverStatus::kNonFinite, "the loss is not finite");
    *cost = value;
    if (gradient) {
      const VectorXd g = ParameterGradient(sim_->Backward(rollout_, dl), num_steps_);
      std::copy(g.data(), g.data() + g.size(), gradient);
      ++stats_.gradients;
    }
    ok = true;
  } catch (const SolverError& e) {
    Fail(std::string("loss gradient failed (") + ToString(e.status()) + "): " + e.what());
  } catch (const InvalidInputError& e) {
    Fail(std::string("loss gradient rejected: ") + e.what());
  } catch (const std::exception& e) {
    Fail(std::string("loss gradient error: ") + e.what());
  }
  if (gradient) stats_.backward_seconds += Seconds(start);
  return ok;
}

}  // namespace diffpd::solvers
