// Scalar functions of a recorded trajectory (TrajectoryFunctional with one
// value), used as objective terms, constraints and losses: marker and
// centre-of-mass coordinates at a step, travel between steps, squared
// distance to a target, and the tilt of a body axis.
//
// Steps are state indices 0..K (state k is after k time steps); kFinalState
// means K, whatever K is.
#pragma once

#include <string>
#include <vector>

#include "diffpd/rollout.h"
#include "diffpd/solvers/core/trajectory_functional.h"
#include "diffpd/types.h"

namespace diffpd::solvers {

inline constexpr int kFinalState = -1;

// A point that moves with the body: p(x) = sum_i w_i x_i (weights over the
// n nodes, summing to 1).
struct TrackedPoint {
  VectorXd node_weights;  // n
  // p (3) at positions x (3n).
  Vec3 At(const VectorXd& x) const;
};
// The node itself (e.g. a marker on a vertex).
TrackedPoint NodePoint(int num_nodes, int node);
// The unweighted mean of `nodes`.
TrackedPoint MeanOf(int num_nodes, const std::vector<int>& nodes);
// The centre of mass: weights m_i / sum m, from the lumped mass per DoF
// (3n, e.g. Simulator::LumpedMass()).
TrackedPoint CentreOfMass(const VectorXd& lumped_mass);

class TrajectoryFunction : public TrajectoryFunctional {
 public:
  // The latest state index the function reads in a rollout of K steps.
  virtual int LastState(int num_steps) const = 0;
  // The value on `rollout`, which must hold at least LastState(K) + 1 states.
  virtual double Value(const Rollout& rollout) const = 0;
  // Adds weight * dF/dx_k and weight * dF/dv_k into `loss` (sized for
  // `rollout`, allocating empty entries as needed).
  virtual void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const = 0;

  // TrajectoryFunctional, in terms of the three above.
  int num_values() const final { return 1; }
  int LastStateOf(int i, int num_steps) const final { return LastState(num_steps); }
  void Evaluate(const Rollout& rollout, Eigen::Ref<VectorXd> values) const final { values(0) = Value(rollout); }
  void AddWeightedGradient(const Rollout& rollout, const Eigen::Ref<const VectorXd>& weights,
                           LossGradient* loss) const final {
    AddGradient(rollout, weights(0), loss);
  }
};

// direction . p(x_k): a coordinate of a marker or of the centre of mass
// (terminal constraints with k = kFinalState, path constraints at other k).
class PointCoordinate : public TrajectoryFunction {
 public:
  // Throws InvalidInputError if step < -1 or direction is not finite.
  PointCoordinate(TrackedPoint point, int step, Vec3 direction, std::string name = "point_coordinate");
  std::string name() const override { return name_; }
  int LastState(int num_steps) const override;
  double Value(const Rollout& rollout) const override;
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;

 private:
  TrackedPoint point_;
  int step_;
  Vec3 direction_;
  std::string name_;
};

// direction . (p(x_to) - p(x_from)): how far a point travelled (m).
class PointTravel : public TrajectoryFunction {
 public:
  // Throws InvalidInputError if a step is < -1 or direction is not finite.
  PointTravel(TrackedPoint point, int from_step, int to_step, Vec3 direction, std::string name = "point_travel");
  std::string name() const override { return name_; }
  int LastState(int num_steps) const override;
  double Value(const Rollout& rollout) const override;
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;

 private:
  TrackedPoint point_;
  int from_, to_;
  Vec3 direction_;
  std::string name_;
};

// sum_a w_a (p_a(x_k) - target_a)^2 (m^2), axis weights w (default 1, 1, 1:
// the squared distance; e.g. (1, 1, 0) ignores height).
class PointDistanceSquared : public TrajectoryFunction {
 public:
  // Throws InvalidInputError if step < -1, target is not finite or a weight
  // is not finite and >= 0.
  PointDistanceSquared(TrackedPoint point, int step, Vec3 target, std::string name = "distance_squared",
                       Vec3 axis_weights = Vec3::Ones());
  std::string name() const override { return name_; }
  int LastState(int num_steps) const override;
  double Value(const Rollout& rollout) const override;
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;

 private:
  TrackedPoint point_;
  int step_;
  Vec3 target_;
  std::string name_;
  Vec3 weights_;
};

// The cosine of the angle between the body axis a -> b at state k and a
// fixed unit direction u:  (p_b - p_a) . u / |p_b - p_a|.  With u = up,
// a bound cos >= c keeps the body from tipping over.
class AxisAlignment : public TrajectoryFunction {
 public:
  // Throws InvalidInputError if step < -1 or direction is not finite and
  // non-zero (it is normalised).
  AxisAlignment(TrackedPoint a, TrackedPoint b, int step, Vec3 direction, std::string name = "axis_alignment");
  std::string name() const override { return name_; }
  int LastState(int num_steps) const override;
  double Value(const Rollout& rollout) const override;
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;

 private:
  TrackedPoint a_, b_;
  int step_;
  Vec3 direction_;
  std::string name_;
};

}  // namespace diffpd::solvers
