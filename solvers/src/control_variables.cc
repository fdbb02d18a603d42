#include "diffpd/solvers/control_variables.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void CheckNodes(const std::vector<int>& nodes, const std::string& what) {
  if (nodes.empty()) throw InvalidInputError(what + ": the node list is empty");
  for (int node : nodes)
    if (node < 0) {
      std::ostringstream msg;
      msg << what << ": node " << node << " is invalid: must be >= 0";
      throw InvalidInputError(msg.str());
    }
}

void CheckNodesFit(const std::vector<int>& nodes, int num_nodes, const std::string& what) {
  for (int node : nodes)
    if (node >= num_nodes) {
      std::ostringstream msg;
      msg << what << ": node " << node << " is out of range: the mesh has " << num_nodes << " nodes";
      throw InvalidInputError(msg.str());
    }
}

// Sum of the 3-vectors of `v` (3n) at `nodes`, projected on `direction`.
double SumAlong(const VectorXd& v, const std::vector<int>& nodes, const Vec3& direction) {
  double sum = 0;
  for (int node : nodes) sum += direction.dot(v.segment<3>(3 * node));
  return sum;
}

}  // namespace

ControlVariables::ControlVariables(int size) { Append(size); }

void ControlVariables::Append(int count) {
  const Eigen::Index old = initial_.size();
  lower_.conservativeResize(old + count);
  upper_.conservativeResize(old + count);
  initial_.conservativeResize(old + count);
  lower_.tail(count).setConstant(-kInf);
  upper_.tail(count).setConstant(kInf);
  initial_.tail(count).setZero();
}

void ControlVariables::SetBounds(double lower, double upper) { SetBounds(0, size(), lower, upper); }

void ControlVariables::SetBounds(int offset, int count, double lower, double upper) {
  if (offset < 0 || count < 0 || offset + count > size()) {
    std::ostringstream msg;
    msg << name() << ": bounds for variables [" << offset << ", " << offset + count << ") are out of range [0, "
        << size() << ")";
    throw InvalidInputError(msg.str());
  }
  if (std::isnan(lower) || std::isnan(upper) || lower > upper) {
    std::ostringstream msg;
    msg << name() << ": bounds [" << lower << ", " << upper << "] are invalid: need lower <= upper, no NaN";
    throw InvalidInputError(msg.str());
  }
  lower_.segment(offset, count).setConstant(lower);
  upper_.segment(offset, count).setConstant(upper);
}

void ControlVariables::SetInitial(const VectorXd& values) {
  if (values.size() != size() || !values.allFinite()) {
    std::ostringstream msg;
    msg << name() << ": starting values have " << values.size() << " entries (expected " << size() << ", all finite)";
    throw InvalidInputError(msg.str());
  }
  initial_ = values;
}

// ---- InitialStateVariables --------------------------------------------------

InitialStateVariables::InitialStateVariables(Quantity quantity, std::vector<int> nodes, Sharing sharing)
    : ControlVariables(sharing == kShared ? 3 : 3 * static_cast<int>(nodes.size())),
      quantity_(quantity),
      nodes_(std::move(nodes)),
      sharing_(sharing) {
  CheckNodes(nodes_, name());
}

std::string InitialStateVariables::name() const {
  return quantity_ == kPosition ? "initial_position" : "initial_velocity";
}

void InitialStateVariables::CheckFits(const Scene& scene, int num_steps) const {
  CheckNodesFit(nodes_, scene.mesh.num_vertices(), name());
}

void InitialStateVariables::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  VectorXd& target = quantity_ == kPosition ? setup->initial.x : setup->initial.v;
  for (size_t i = 0; i < nodes_.size(); ++i)
    target.segment<3>(3 * nodes_[i]) += values.segment<3>(sharing_ == kShared ? 0 : 3 * i);
}

void InitialStateVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                     Eigen::Ref<VectorXd> out) const {
  const VectorXd& g = quantity_ == kPosition ? grad.x0 : grad.v0;
  out.setZero();
  for (size_t i = 0; i < nodes_.size(); ++i)
    out.segment<3>(sharing_ == kShared ? 0 : 3 * i) += g.segment<3>(3 * nodes_[i]);
}

bool InitialStateVariables::AddDirection(const Eigen::Ref<const VectorXd>& values, int j, int num_steps,
                                         InputDirection* direction) const {
  VectorXd& target = quantity_ == kPosition ? direction->x0 : direction->v0;
  const int axis = j % 3;
  if (sharing_ == kShared) {
    for (int node : nodes_) target(3 * node + axis) += 1;
  } else {
    target(3 * nodes_[j / 3] + axis) += 1;
  }
  return true;
}

// ---- ExternalForceControl ---------------------------------------------------

ExternalForceControl::ExternalForceControl(std::vector<Channel> channels)
    : ControlVariables(0), channels_(std::move(channels)) {
  if (channels_.empty()) throw InvalidInputError("external_force: no channel");
  offsets_.push_back(0);
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "external_force channel " + std::to_string(c);
    CheckNodes(channels_[c].nodes, what);
    if (!channels_[c].signal) throw InvalidInputError(what + ": no signal");
    if (!channels_[c].direction.allFinite()) throw InvalidInputError(what + ": the direction is not finite");
    if (channels_[c].signal->num_steps() != channels_[0].signal->num_steps()) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, channel 0's has "
          << channels_[0].signal->num_steps();
      throw InvalidInputError(msg.str());
    }
    const int p = channels_[c].signal->num_coefficients();
    Append(p);
    offsets_.push_back(offsets_.back() + p);
  }
}

void ExternalForceControl::CheckFits(const Scene& scene, int num_steps) const {
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "external_force channel " + std::to_string(c);
    CheckNodesFit(channels_[c].nodes, scene.mesh.num_vertices(), what);
    if (channels_[c].signal->num_steps() != num_steps) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, the rollout has " << num_steps;
      throw InvalidInputError(msg.str());
    }
  }
}

void ExternalForceControl::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  const Eigen::Index n = setup->initial.x.size();
  VectorXd s;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], offsets_[c + 1] - offsets_[c]), &s, nullptr);
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      VectorXd& f = setup->inputs[k].external_force;
      if (f.size() == 0) f = VectorXd::Zero(n);
      for (int node : ch.nodes) f.segment<3>(3 * node) += s(k) * ch.direction;
    }
  }
}

void ExternalForceControl::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                    Eigen::Ref<VectorXd> out) const {
  VectorXd ds;
  MatrixXd jacobian;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    const int p = offsets_[c + 1] - offsets_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], p), nullptr, &jacobian);
    ds = VectorXd::Zero(ch.signal->num_steps());
    const Eigen::Index known = std::min<Eigen::Index>(ds.size(), grad.external_force.size());
    for (Eigen::Index k = 0; k < known; ++k)
      if (grad.external_force[k].size()) ds(k) = SumAlong(grad.external_force[k], ch.nodes, ch.direction);
    out.segment(offsets_[c], p) = jacobian.transpose() * ds;
  }
}

int ExternalForceControl::FirstAffectedState(int j) const {
  int c = 0;
  while (offsets_[c + 1] <= j) ++c;
  return channels_[c].signal->FirstStep(j - offsets_[c]) + 1;
}

bool ExternalForceControl::AddDirection(const Eigen::Ref<const VectorXd>& values, int j, int num_steps,
                                        InputDirection* direction) const {
  int c = 0;
  while (offsets_[c + 1] <= j) ++c;
  const Channel& ch = channels_[c];
  MatrixXd jacobian;
  ch.signal->Evaluate(values.segment(offsets_[c], offsets_[c + 1] - offsets_[c]), nullptr, &jacobian);
  const Eigen::Index n = direction->x0.size();
  for (int k = 0; k < num_steps; ++k) {
    const double ds = jacobian(k, j - offsets_[c]);
    if (ds == 0) continue;
    VectorXd& f = direction->external_force[k];
    if (f.size() == 0) f = VectorXd::Zero(n);
    for (int node : ch.nodes) f.segment<3>(3 * node) += ds * ch.direction;
  }
  return true;
}

// ---- MaterialVariables ------------------------------------------------------

MaterialVariables::MaterialVariables(std::vector<Entry> entries, const MaterialParameters& start)
    : ControlVariables(static_cast<int>(entries.size())), entries_(std::move(entries)) {
  if (entries_.empty()) throw InvalidInputError("material: no parameter");
  VectorXd initial(entries_.size());
  for (size_t i = 0; i < entries_.size(); ++i) {
    for (size_t j = 0; j < i; ++j)
      if (entries_[j].field == entries_[i].field) throw InvalidInputError("material: a parameter is listed twice");
    if (!(std::isfinite(entries_[i].scale) && entries_[i].scale > 0)) {
      std::ostringstream msg;
      msg << "material: scale = " << entries_[i].scale << " is invalid: must be finite and > 0";
      throw InvalidInputError(msg.str());
    }
    const double value = entries_[i].field == kYoungsModulus   ? start.youngs_modulus
                         : entries_[i].field == kPoissonsRatio ? start.poissons_ratio
                                                               : start.density;
    initial(i) = value / entries_[i].scale;
  }
  SetInitial(initial);
}

void MaterialVariables::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  for (size_t i = 0; i < entries_.size(); ++i) {
    const double value = values(i) * entries_[i].scale;
    switch (entries_[i].field) {
      case kYoungsModulus:
        setup->material.youngs_modulus = value;
        break;
      case kPoissonsRatio:
        setup->material.poissons_ratio = value;
        break;
      case kDensity:
        setup->material.density = value;
        break;
    }
  }
}

void MaterialVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                 Eigen::Ref<VectorXd> out) const {
  for (size_t i = 0; i < entries_.size(); ++i) {
    const double g = entries_[i].field == kYoungsModulus   ? grad.youngs_modulus
                     : entries_[i].field == kPoissonsRatio ? grad.poissons_ratio
                                                           : grad.density;
    out(i) = g * entries_[i].scale;
  }
}

bool MaterialVariables::AddDirection(const Eigen::Ref<const VectorXd>& values, int j, int num_steps,
                                     InputDirection* direction) const {
  const double scale = entries_[j].scale;
  switch (entries_[j].field) {
    case kYoungsModulus:
      direction->youngs_modulus += scale;
      break;
    case kPoissonsRatio:
      direction->poissons_ratio += scale;
      break;
    case kDensity:
      direction->density += scale;
      break;
  }
  return true;
}

// ---- ActivationControl ------------------------------------------------------

ActivationControl::ActivationControl(std::vector<Channel> channels)
    : ControlVariables(0), channels_(std::move(channels)) {
  if (channels_.empty()) throw InvalidInputError("activation: no channel");
  offsets_.push_back(0);
  VectorXd initial;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "activation channel " + std::to_string(c);
    if (channels_[c].muscle < 0) {
      std::ostringstream msg;
      msg << what << ": muscle " << channels_[c].muscle << " is invalid: must be >= 0";
      throw InvalidInputError(msg.str());
    }
    for (size_t d = 0; d < c; ++d)
      if (channels_[d].muscle == channels_[c].muscle) {
        std::ostringstream msg;
        msg << what << ": muscle " << channels_[c].muscle << " is already driven by channel " << d;
        throw InvalidInputError(msg.str());
      }
    if (!channels_[c].signal) throw InvalidInputError(what + ": no signal");
    if (channels_[c].signal->num_steps() != channels_[0].signal->num_steps()) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, channel 0's has "
          << channels_[0].signal->num_steps();
      throw InvalidInputError(msg.str());
    }
    const int p = channels_[c].signal->num_coefficients();
    Append(p);
    offsets_.push_back(offsets_.back() + p);
    initial.conservativeResize(offsets_.back());
    initial.tail(p) = channels_[c].signal->ConstantCoefficients(1.0);
  }
  SetInitial(initial);
}

void ActivationControl::CheckFits(const Scene& scene, int num_steps) const {
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "activation channel " + std::to_string(c);
    if (channels_[c].muscle >= static_cast<int>(scene.muscles.size())) {
      std::ostringstream msg;
      msg << what << ": muscle " << channels_[c].muscle << " is out of range: the scene has " << scene.muscles.size()
          << " muscles";
      throw InvalidInputError(msg.str());
    }
    if (channels_[c].signal->num_steps() != num_steps) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, the rollout has " << num_steps;
      throw InvalidInputError(msg.str());
    }
  }
}

void ActivationControl::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  VectorXd s;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], offsets_[c + 1] - offsets_[c]), &s, nullptr);
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      VectorXd& a = setup->inputs[k].activation;
      if (a.size() <= ch.muscle) {
        const Eigen::Index old = a.size();
        a.conservativeResize(ch.muscle + 1);
        a.tail(a.size() - old).setOnes();
      }
      a(ch.muscle) = s(k);
    }
  }
}

void ActivationControl::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                 Eigen::Ref<VectorXd> out) const {
  VectorXd ds;
  MatrixXd jacobian;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    const int p = offsets_[c + 1] - offsets_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], p), nullptr, &jacobian);
    ds = VectorXd::Zero(ch.signal->num_steps());
    const Eigen::Index known = std::min<Eigen::Index>(ds.size(), grad.activation.size());
    for (Eigen::Index k = 0; k < known; ++k)
      if (grad.activation[k].size() > ch.muscle) ds(k) = grad.activation[k](ch.muscle);
    out.segment(offsets_[c], p) = jacobian.transpose() * ds;
  }
}

int ActivationControl::FirstAffectedState(int j) const {
  int c = 0;
  while (offsets_[c + 1] <= j) ++c;
  return channels_[c].signal->FirstStep(j - offsets_[c]) + 1;
}

}  // namespace diffpd::solvers
