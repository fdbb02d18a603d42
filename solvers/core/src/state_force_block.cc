#include "diffpd/solvers/core/state_force_block.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

bool Hydrodynamic(StateForceField f) {
  return f != StateForceField::kLinearDamping && f != StateForceField::kPenaltyFriction;
}

// Throws unless `scene` declares the entry's term.
void CheckDeclared(int i, const StateForceBlock::Entry& e, const Scene& scene) {
  std::ostringstream msg;
  msg << "state_forces: entry " << i << ": ";
  if (e.field == StateForceField::kLinearDamping && !scene.linear_damping) {
    msg << "linear_damping is not declared by the scene";
    throw InvalidInputError(msg.str());
  }
  if (Hydrodynamic(e.field) && !scene.hydrodynamics) {
    msg << ToString(e.field) << " is not declared by the scene (it has no hydrodynamics)";
    throw InvalidInputError(msg.str());
  }
  if (e.field == StateForceField::kPenaltyFriction) {
    const int contacts = static_cast<int>(scene.penalty_contacts.size());
    if (e.contact < 0 || e.contact >= contacts) {
      msg << "penalty contact " << e.contact << " is out of range [0, " << contacts << ")";
      throw InvalidInputError(msg.str());
    }
    if (scene.penalty_contacts[e.contact].friction == 0) {
      msg << "penalty contact " << e.contact << " has friction 0: a fitted friction must start > 0";
      throw InvalidInputError(msg.str());
    }
  }
}

double& Value(StateForceParameters* p, const StateForceBlock::Entry& e) {
  switch (e.field) {
    case StateForceField::kLinearDamping:
      return p->linear_damping;
    case StateForceField::kFluidDensity:
      return p->fluid_density;
    case StateForceField::kDragTangential:
      return p->drag_tangential;
    case StateForceField::kDragNormal:
      return p->drag_normal;
    case StateForceField::kThrust:
      return p->thrust;
    case StateForceField::kFlowVelocityX:
      return p->flow_velocity(0);
    case StateForceField::kFlowVelocityY:
      return p->flow_velocity(1);
    case StateForceField::kFlowVelocityZ:
      return p->flow_velocity(2);
    case StateForceField::kPenaltyFriction:
      return p->penalty_friction[e.contact];
  }
  DIFFPD_CHECK(false, "unknown StateForceField " << static_cast<int>(e.field));
}

double Gradient(const StateForceGradient& g, const StateForceBlock::Entry& e) {
  switch (e.field) {
    case StateForceField::kLinearDamping:
      return g.linear_damping;
    case StateForceField::kFluidDensity:
      return g.fluid_density;
    case StateForceField::kDragTangential:
      return g.drag_tangential;
    case StateForceField::kDragNormal:
      return g.drag_normal;
    case StateForceField::kThrust:
      return g.thrust;
    case StateForceField::kFlowVelocityX:
      return g.flow_velocity(0);
    case StateForceField::kFlowVelocityY:
      return g.flow_velocity(1);
    case StateForceField::kFlowVelocityZ:
      return g.flow_velocity(2);
    case StateForceField::kPenaltyFriction:
      return e.contact < static_cast<int>(g.penalty_friction.size()) ? g.penalty_friction[e.contact] : 0.0;
  }
  DIFFPD_CHECK(false, "unknown StateForceField " << static_cast<int>(e.field));
}

}  // namespace

const char* ToString(StateForceField field) {
  switch (field) {
    case StateForceField::kLinearDamping:
      return "linear_damping";
    case StateForceField::kFluidDensity:
      return "fluid_density";
    case StateForceField::kDragTangential:
      return "drag_tangential";
    case StateForceField::kDragNormal:
      return "drag_normal";
    case StateForceField::kThrust:
      return "thrust";
    case StateForceField::kFlowVelocityX:
      return "flow_velocity_x";
    case StateForceField::kFlowVelocityY:
      return "flow_velocity_y";
    case StateForceField::kFlowVelocityZ:
      return "flow_velocity_z";
    case StateForceField::kPenaltyFriction:
      return "penalty_friction";
  }
  return "unknown";
}

StateForceBlock::StateForceBlock(std::vector<Entry> entries, const Scene& scene)
    : ParameterBlock(static_cast<int>(entries.size())), entries_(std::move(entries)) {
  if (entries_.empty()) throw InvalidInputError("state_forces: no parameter");
  StateForceParameters start = StateForceParameters::Of(scene);
  VectorXd initial(entries_.size());
  for (size_t i = 0; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    if (!(std::isfinite(e.scale) && e.scale > 0)) {
      std::ostringstream msg;
      msg << "state_forces: entry " << i << ": scale = " << e.scale << " is invalid: must be finite and > 0";
      throw InvalidInputError(msg.str());
    }
    CheckDeclared(static_cast<int>(i), e, scene);
    for (size_t j = 0; j < i; ++j)
      if (entries_[j].field == e.field &&
          (e.field != StateForceField::kPenaltyFriction || entries_[j].contact == e.contact)) {
        std::ostringstream msg;
        msg << "state_forces: entry " << i << " lists " << ToString(e.field);
        if (e.field == StateForceField::kPenaltyFriction) msg << " of penalty contact " << e.contact;
        msg << " again";
        throw InvalidInputError(msg.str());
      }
    initial(static_cast<Eigen::Index>(i)) = Value(&start, e) / e.scale;
  }
  SetInitial(initial);
}

void StateForceBlock::CheckFits(const Scene& scene, int num_steps) const {
  for (size_t i = 0; i < entries_.size(); ++i) CheckDeclared(static_cast<int>(i), entries_[i], scene);
}

void StateForceBlock::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  for (size_t i = 0; i < entries_.size(); ++i) Value(&setup->state_forces, entries_[i]) = values(i) * entries_[i].scale;
}

void StateForceBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                               Eigen::Ref<VectorXd> out) const {
  for (size_t i = 0; i < entries_.size(); ++i) out(i) = Gradient(grad.state_forces, entries_[i]) * entries_[i].scale;
}

void StateForceBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                                  InputDirection* direction) const {
  const Entry& e = entries_[j];
  StateForceGradient& d = direction->state_forces;
  switch (e.field) {
    case StateForceField::kLinearDamping:
      d.linear_damping += e.scale;
      return;
    case StateForceField::kFluidDensity:
      d.fluid_density += e.scale;
      return;
    case StateForceField::kDragTangential:
      d.drag_tangential += e.scale;
      return;
    case StateForceField::kDragNormal:
      d.drag_normal += e.scale;
      return;
    case StateForceField::kThrust:
      d.thrust += e.scale;
      return;
    case StateForceField::kFlowVelocityX:
      d.flow_velocity(0) += e.scale;
      return;
    case StateForceField::kFlowVelocityY:
      d.flow_velocity(1) += e.scale;
      return;
    case StateForceField::kFlowVelocityZ:
      d.flow_velocity(2) += e.scale;
      return;
    case StateForceField::kPenaltyFriction:
      if (d.penalty_friction.size() != setup.state_forces.penalty_friction.size())
        d.penalty_friction.assign(setup.state_forces.penalty_friction.size(), 0.0);
      d.penalty_friction[e.contact] += e.scale;
      return;
  }
  DIFFPD_CHECK(false, "unknown StateForceField " << static_cast<int>(e.field));
}

}  // namespace diffpd::solvers
