// A scene: what a simulation contains. A scene declares only what it needs;
// every force and energy it does not declare is never evaluated.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "diffpd/contact.h"
#include "diffpd/material.h"
#include "diffpd/mesh.h"
#include "diffpd/muscle.h"
#include "diffpd/state_forces.h"
#include "diffpd/types.h"

namespace diffpd {

// Degrees of freedom held at prescribed positions. DoF d is axis d % 3 of
// node d / 3. The simulator erases these DoFs from every solve: their position
// stays at `values` and their velocity is (x_{i+1} - x_i) / h.
struct DirichletBoundary {
  std::vector<int> dofs;  // strictly increasing DoF indices in [0, 3n)
  VectorXd values;        // same length as dofs, metres
};

// A set of elements with a material of their own. Regions are numbered by
// their position in Scene::material_regions (0, 1, ...); an element listed in
// no region has the base material Scene::material.
struct MaterialRegion {
  // Element indices in [0, mesh.num_elements()), no repetition; non-empty.
  // An element may belong to at most one region.
  std::vector<int> elements;
  MaterialParameters material;
};

// How the body's mass is spread over its nodes (inertia and gravity).
enum class MassLumping {
  kLumped,      // node a carries the integral of its shape function N_a times rho (the body's true mass)
  kEqualNodes,  // every node carries rho times the mean element volume, as the original DiffPD code
                // does (its total exceeds the body's mass; for reproducing its scenes)
};
// "lumped", "equal-nodes", and back; Parse throws InvalidInputError for any
// other name ("masses 'x' is unknown: use lumped or equal-nodes").
const char* ToString(MassLumping lumping);
MassLumping ParseMassLumping(const std::string& name);

struct Scene {
  Mesh mesh;
  // The base material: that of every element in no material region.
  MaterialParameters material;
  // Optional per-region materials (Young's modulus, Poisson's ratio and
  // density per region). Empty: the whole body has `material` and costs
  // nothing extra. Simulator::SetRegionMaterial changes one region's values;
  // RolloutGradient::region_materials and InputDirection::region_materials
  // hold the derivatives, one entry per region in this order.
  std::vector<MaterialRegion> material_regions;
  // Elastic energy densities, summed. PD solvers need all of them projective
  // (kPdCorotated, kPdVolume); Newton and PD-LBFGS accept any.
  std::vector<ElasticEnergy> energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  // kEqualNodes needs a single material (no material_regions).
  MassLumping mass_lumping = MassLumping::kLumped;
  // Uniform gravitational acceleration (m/s^2), applied as M g when declared.
  std::optional<Vec3> gravity;
  DirichletBoundary dirichlet;

  // Optional terms; each costs nothing unless declared (empty / unset).
  // Muscle actuators (muscle.h); StepInput::activation drives them.
  std::vector<Muscle> muscles;
  // Frictional contact surfaces with their candidate nodes (contact.h).
  std::vector<FrictionalContact> frictional_contacts;
  FrictionalContactOptions frictional_contact_options;
  // Penalty contact half-spaces (contact.h).
  std::vector<PenaltyContact> penalty_contacts;
  // State forces (state_forces.h): drag and thrust on surface triangles, and
  // mass-proportional damping f = -c M v (c in 1/s).
  std::optional<Hydrodynamics> hydrodynamics;
  // The original DiffPD swimmers' drag and thrust on one-sided quads with
  // Bezier coefficient curves (quad_hydrodynamics.h).
  std::optional<QuadHydrodynamics> quad_hydrodynamics;
  std::optional<double> linear_damping;

  // Throws InvalidInputError naming the first problem: invalid mesh or
  // material; a material region that is empty ("scene: material region 1 has
  // no element"), lists an element out of range ("scene: material region 1
  // lists element 40, out of range [0, 32)") or twice ("scene: material
  // region 1 lists element 5 twice"), shares an element with an earlier
  // region ("scene: element 5 is in material regions 0 and 1") or has an
  // invalid material ("scene: material region 1: youngs_modulus = 0 is
  // invalid: ..."); no energy or one that is no ElasticEnergy ("scene:
  // energies[1] = 9 is invalid: must be an ElasticEnergy, 0 (linear) to 4
  // (pd-volume)"), a mass_lumping that is no MassLumping ("scene: mass_lumping = 7 is
  // invalid: must be 0 (lumped) or 1 (equal-nodes)") or kEqualNodes with material regions
  // ("scene: mass_lumping = equal-nodes needs a single material (2 material regions declared)"),
  // Dirichlet DoF out of range or not increasing, a size mismatch, or a non-finite gravity/Dirichlet
  // value; then the optional terms (messages listed in muscle.h, contact.h and state_forces.h).
  void Validate() const;
};

// Fixes all three axes of `nodes` at their rest positions (sorted, merged
// with the existing Dirichlet DoFs). Throws InvalidInputError for a node out
// of range ("FixNodes: node 99 is out of range [0, 50)"); the scene is then
// unchanged.
void FixNodes(Scene* scene, const std::vector<int>& nodes);
// Fixes the given axes (0 = x, 1 = y, 2 = z) of `nodes` at rest positions.
// Throws InvalidInputError, the scene unchanged, for an axis outside 0..2
// ("FixNodeAxes: axis 5 is invalid: must be 0 (x), 1 (y) or 2 (z)") or a
// node out of range ("FixNodeAxes: node -1 is out of range [0, 50)").
void FixNodeAxes(Scene* scene, const std::vector<int>& nodes, const std::vector<int>& axes);

}  // namespace diffpd
