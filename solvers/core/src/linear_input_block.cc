#include "diffpd/solvers/core/linear_input_block.h"

#include <algorithm>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

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

int BlockSize(const MatrixXd& x, const MatrixXd& v, const MatrixXd& f) {
  int columns = -1;
  CheckBasis(x, "position_basis", &columns);
  CheckBasis(v, "velocity_basis", &columns);
  CheckBasis(f, "force_basis", &columns);
  if (columns <= 0) throw InvalidInputError("linear_input: no basis with at least one column given");
  return columns;
}

}  // namespace

LinearInputBlock::LinearInputBlock(MatrixXd position_basis, MatrixXd velocity_basis, MatrixXd force_basis,
                                   int force_begin, int force_end)
    : ParameterBlock(BlockSize(position_basis, velocity_basis, force_basis)),
      position_(std::move(position_basis)),
      velocity_(std::move(velocity_basis)),
      force_(std::move(force_basis)),
      force_begin_(force_begin),
      force_end_(force_end) {
  if (force_begin_ < 0 || force_end_ < force_begin_) {
    std::ostringstream msg;
    msg << "force_begin = " << force_begin_ << ", force_end = " << force_end_ << " is invalid: need 0 <= begin <= end";
    throw InvalidInputError(msg.str());
  }
}

void LinearInputBlock::CheckFits(const Scene& scene, int num_steps) const {
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(scene.mesh.num_vertices());
  for (const MatrixXd* b : {&position_, &velocity_, &force_})
    if (b->size() && b->rows() != n) {
      std::ostringstream msg;
      msg << name() << ": a basis has " << b->rows() << " rows but the scene has " << n << " DoFs";
      throw InvalidInputError(msg.str());
    }
}

void LinearInputBlock::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  const Eigen::Index n = setup->initial.x.size();
  if (position_.size()) setup->initial.x += position_ * values;
  if (velocity_.size()) setup->initial.v += velocity_ * values;
  const int end = std::min(force_end_, static_cast<int>(setup->inputs.size()));
  if (force_.size() && end > force_begin_) {
    const VectorXd f = force_ * values;
    for (int k = force_begin_; k < end; ++k) {
      VectorXd& fk = setup->inputs[k].external_force;
      if (fk.size() == 0) fk = VectorXd::Zero(n);
      fk += f;
    }
  }
}

void LinearInputBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                Eigen::Ref<VectorXd> out) const {
  out.setZero();
  if (position_.size()) out.noalias() += position_.transpose() * grad.x0;
  if (velocity_.size()) out.noalias() += velocity_.transpose() * grad.v0;
  if (force_.size()) {
    const int end = std::min(force_end_, static_cast<int>(grad.external_force.size()));
    for (int k = force_begin_; k < end; ++k)
      if (grad.external_force[k].size()) out.noalias() += force_.transpose() * grad.external_force[k];
  }
}

int LinearInputBlock::FirstAffectedState(int j) const {
  if ((position_.size() && position_.col(j).any()) || (velocity_.size() && velocity_.col(j).any())) return 0;
  if (force_.size() && force_.col(j).any() && force_end_ > force_begin_) return force_begin_ + 1;
  return kAffectsNoState;
}

void LinearInputBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                                   InputDirection* direction) const {
  if (position_.size()) direction->x0 += position_.col(j);
  if (velocity_.size()) direction->v0 += velocity_.col(j);
  const int end = std::min(force_end_, static_cast<int>(setup.inputs.size()));
  if (force_.size())
    for (int k = force_begin_; k < end; ++k) {
      VectorXd& f = direction->external_force[k];
      if (f.size() == 0) f = VectorXd::Zero(direction->x0.size());
      f += force_.col(j);
    }
}

}  // namespace diffpd::solvers
