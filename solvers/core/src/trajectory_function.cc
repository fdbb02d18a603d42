#include "diffpd/solvers/core/trajectory_function.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

int Resolve(int step, int num_steps) { return step == kFinalState ? num_steps : step; }

void CheckStep(int step, const std::string& what) {
  if (step < kFinalState) {
    std::ostringstream msg;
    msg << what << ": step " << step << " is invalid: must be a state index >= 0 or kFinalState (-1)";
    throw InvalidInputError(msg.str());
  }
}

const VectorXd& PositionsAt(const Rollout& rollout, int step, const std::string& what) {
  const int k = Resolve(step, rollout.num_steps());
  if (k >= static_cast<int>(rollout.states.size())) {
    std::ostringstream msg;
    msg << what << ": reads state " << k << " but the rollout has " << rollout.states.size() << " states";
    throw InvalidInputError(msg.str());
  }
  return rollout.states[k].x;
}

// loss.dx[k] += weight * (w_i g) for every node i.
void AddPointGradient(const Rollout& rollout, int step, const TrackedPoint& point, const Vec3& g, double weight,
                      LossGradient* loss) {
  const int k = Resolve(step, rollout.num_steps());
  const Eigen::Index n3 = rollout.states[k].x.size();
  if (static_cast<int>(loss->dx.size()) < rollout.num_steps() + 1) {
    loss->dx.resize(rollout.num_steps() + 1);
    loss->dv.resize(rollout.num_steps() + 1);
  }
  VectorXd& dx = loss->dx[k];
  if (dx.size() == 0) dx = VectorXd::Zero(n3);
  for (Eigen::Index i = 0; i < point.node_weights.size(); ++i)
    if (point.node_weights(i) != 0) dx.segment<3>(3 * i) += (weight * point.node_weights(i)) * g;
}

Vec3 CheckedFinite(const Vec3& v, const std::string& what, const char* label = "direction") {
  if (!v.allFinite()) throw InvalidInputError(what + ": the " + label + " is not finite");
  return v;
}

}  // namespace

Vec3 TrackedPoint::At(const VectorXd& x) const {
  DIFFPD_CHECK(x.size() == 3 * node_weights.size(),
               "tracked point over " << node_weights.size() << " nodes evaluated on " << x.size() << " DoFs");
  return Eigen::Map<const Eigen::Matrix3Xd>(x.data(), 3, node_weights.size()) * node_weights;
}

TrackedPoint NodePoint(int num_nodes, int node) {
  if (node < 0 || node >= num_nodes) {
    std::ostringstream msg;
    msg << "marker node " << node << " is out of range [0, " << num_nodes << ")";
    throw InvalidInputError(msg.str());
  }
  TrackedPoint p{VectorXd::Zero(num_nodes)};
  p.node_weights(node) = 1;
  return p;
}

TrackedPoint MeanOf(int num_nodes, const std::vector<int>& nodes) {
  if (nodes.empty()) throw InvalidInputError("mean point: the node list is empty");
  TrackedPoint p{VectorXd::Zero(num_nodes)};
  for (int node : nodes) {
    if (node < 0 || node >= num_nodes) {
      std::ostringstream msg;
      msg << "mean point: node " << node << " is out of range [0, " << num_nodes << ")";
      throw InvalidInputError(msg.str());
    }
    p.node_weights(node) += 1.0 / nodes.size();
  }
  return p;
}

TrackedPoint CentreOfMass(const VectorXd& lumped_mass) {
  if (lumped_mass.size() == 0 || lumped_mass.size() % 3 != 0 || !(lumped_mass.array() >= 0).all() ||
      !(lumped_mass.sum() > 0))
    throw InvalidInputError("centre of mass: the lumped mass must have 3n non-negative entries with a positive sum");
  const Eigen::Index n = lumped_mass.size() / 3;
  TrackedPoint p{VectorXd(n)};
  for (Eigen::Index i = 0; i < n; ++i) p.node_weights(i) = lumped_mass(3 * i);
  p.node_weights /= p.node_weights.sum();
  return p;
}

// ---- PointCoordinate ----------------------------------------------------------

PointCoordinate::PointCoordinate(TrackedPoint point, int step, Vec3 direction, std::string name)
    : point_(std::move(point)), step_(step), direction_(CheckedFinite(direction, name)), name_(std::move(name)) {
  CheckStep(step, name_);
}

int PointCoordinate::LastState(int num_steps) const { return Resolve(step_, num_steps); }

double PointCoordinate::Value(const Rollout& rollout) const {
  return direction_.dot(point_.At(PositionsAt(rollout, step_, name_)));
}

void PointCoordinate::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  AddPointGradient(rollout, step_, point_, direction_, weight, loss);
}

// ---- PointTravel --------------------------------------------------------------

PointTravel::PointTravel(TrackedPoint point, int from_step, int to_step, Vec3 direction, std::string name)
    : point_(std::move(point)),
      from_(from_step),
      to_(to_step),
      direction_(CheckedFinite(direction, name)),
      name_(std::move(name)) {
  CheckStep(from_step, name_);
  CheckStep(to_step, name_);
}

int PointTravel::LastState(int num_steps) const { return std::max(Resolve(from_, num_steps), Resolve(to_, num_steps)); }

double PointTravel::Value(const Rollout& rollout) const {
  return direction_.dot(point_.At(PositionsAt(rollout, to_, name_)) - point_.At(PositionsAt(rollout, from_, name_)));
}

void PointTravel::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  AddPointGradient(rollout, to_, point_, direction_, weight, loss);
  AddPointGradient(rollout, from_, point_, -direction_, weight, loss);
}

// ---- PointDistanceSquared -----------------------------------------------------

PointDistanceSquared::PointDistanceSquared(TrackedPoint point, int step, Vec3 target, std::string name,
                                           Vec3 axis_weights)
    : point_(std::move(point)),
      step_(step),
      target_(CheckedFinite(target, name, "target")),
      name_(std::move(name)),
      weights_(axis_weights) {
  CheckStep(step, name_);
  if (!weights_.allFinite() || (weights_.array() < 0).any())
    throw InvalidInputError(name_ + ": the axis weights must be finite and >= 0");
}

int PointDistanceSquared::LastState(int num_steps) const { return Resolve(step_, num_steps); }

double PointDistanceSquared::Value(const Rollout& rollout) const {
  const Vec3 r = point_.At(PositionsAt(rollout, step_, name_)) - target_;
  return r.cwiseProduct(r).dot(weights_);
}

void PointDistanceSquared::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  const Vec3 r = point_.At(PositionsAt(rollout, step_, name_)) - target_;
  AddPointGradient(rollout, step_, point_, 2 * weights_.cwiseProduct(r), weight, loss);
}

// ---- AxisAlignment ------------------------------------------------------------

AxisAlignment::AxisAlignment(TrackedPoint a, TrackedPoint b, int step, Vec3 direction, std::string name)
    : a_(std::move(a)), b_(std::move(b)), step_(step), name_(std::move(name)) {
  CheckStep(step, name_);
  if (!direction.allFinite() || direction.norm() == 0)
    throw InvalidInputError(name_ + ": the direction must be finite and non-zero");
  direction_ = direction.normalized();
}

int AxisAlignment::LastState(int num_steps) const { return Resolve(step_, num_steps); }

double AxisAlignment::Value(const Rollout& rollout) const {
  const VectorXd& x = PositionsAt(rollout, step_, name_);
  const Vec3 d = b_.At(x) - a_.At(x);
  return d.dot(direction_) / d.norm();
}

void AxisAlignment::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  const VectorXd& x = PositionsAt(rollout, step_, name_);
  const Vec3 d = b_.At(x) - a_.At(x);
  const double len = d.norm();
  // d/dd (d.u / |d|) = u / |d| - (d.u) d / |d|^3.
  const Vec3 g = direction_ / len - d.dot(direction_) * d / (len * len * len);
  AddPointGradient(rollout, step_, b_, g, weight, loss);
  AddPointGradient(rollout, step_, a_, -g, weight, loss);
}

}  // namespace diffpd::solvers
