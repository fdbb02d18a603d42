#include "diffpd/solvers/core/initial_state_block.h"

#include "node_checks.h"

namespace diffpd::solvers {

InitialStateBlock::InitialStateBlock(Quantity quantity, std::vector<int> nodes, Sharing sharing)
    : ParameterBlock(sharing == kShared ? 3 : 3 * static_cast<int>(nodes.size())),
      quantity_(quantity),
      nodes_(std::move(nodes)),
      sharing_(sharing) {
  internal::CheckNodes(nodes_, name());
}

std::string InitialStateBlock::name() const { return quantity_ == kPosition ? "initial_position" : "initial_velocity"; }

void InitialStateBlock::CheckFits(const Scene& scene, int num_steps) const {
  internal::CheckNodesFit(nodes_, scene.mesh.num_vertices(), name());
}

void InitialStateBlock::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  VectorXd& target = quantity_ == kPosition ? setup->initial.x : setup->initial.v;
  for (size_t i = 0; i < nodes_.size(); ++i)
    target.segment<3>(3 * nodes_[i]) += values.segment<3>(sharing_ == kShared ? 0 : 3 * i);
}

void InitialStateBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                 Eigen::Ref<VectorXd> out) const {
  const VectorXd& g = quantity_ == kPosition ? grad.x0 : grad.v0;
  out.setZero();
  for (size_t i = 0; i < nodes_.size(); ++i)
    out.segment<3>(sharing_ == kShared ? 0 : 3 * i) += g.segment<3>(3 * nodes_[i]);
}

void InitialStateBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                                    InputDirection* direction) const {
  VectorXd& target = quantity_ == kPosition ? direction->x0 : direction->v0;
  const int axis = j % 3;
  if (sharing_ == kShared) {
    for (int node : nodes_) target(3 * node + axis) += 1;
  } else {
    target(3 * nodes_[j / 3] + axis) += 1;
  }
}

}  // namespace diffpd::solvers
