#include "diffpd/scene.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "diffpd/error.h"
#include "forces/optional_terms_validation.h"
#include "scene/material_regions.h"

namespace diffpd {

const char* ToString(MassLumping lumping) { return lumping == MassLumping::kEqualNodes ? "equal-nodes" : "lumped"; }

MassLumping ParseMassLumping(const std::string& name) {
  if (name == "lumped") return MassLumping::kLumped;
  if (name == "equal-nodes") return MassLumping::kEqualNodes;
  throw InvalidInputError("masses '" + name + "' is unknown: use lumped or equal-nodes");
}

void Scene::Validate() const {
  ValidateMesh(mesh);
  material.Validate();
  internal::ValidateMaterialRegions(*this);
  if (energies.empty()) throw InvalidInputError("scene: no elastic energy declared (energies is empty)");
  for (size_t k = 0; k < energies.size(); ++k)
    if (!IsElasticEnergy(energies[k])) {
      std::ostringstream msg;
      msg << "scene: energies[" << k << "] = " << static_cast<int>(energies[k])
          << " is invalid: must be an ElasticEnergy, 0 (linear) to 4 (pd-volume)";
      throw InvalidInputError(msg.str());
    }
  if (mass_lumping != MassLumping::kLumped && mass_lumping != MassLumping::kEqualNodes) {
    std::ostringstream msg;
    msg << "scene: mass_lumping = " << static_cast<int>(mass_lumping)
        << " is invalid: must be 0 (lumped) or 1 (equal-nodes)";
    throw InvalidInputError(msg.str());
  }
  if (mass_lumping == MassLumping::kEqualNodes && !material_regions.empty())
    throw InvalidInputError("scene: mass_lumping = equal-nodes needs a single material (" +
                            std::to_string(material_regions.size()) + " material regions declared)");
  if (gravity && !gravity->allFinite()) throw InvalidInputError("scene: gravity has a non-finite component");
  const int n = mesh.num_dofs();
  if (static_cast<Eigen::Index>(dirichlet.dofs.size()) != dirichlet.values.size()) {
    std::ostringstream msg;
    msg << "scene: dirichlet.dofs has " << dirichlet.dofs.size() << " entries but dirichlet.values has "
        << dirichlet.values.size();
    throw InvalidInputError(msg.str());
  }
  for (size_t k = 0; k < dirichlet.dofs.size(); ++k) {
    const int d = dirichlet.dofs[k];
    if (d < 0 || d >= n) {
      std::ostringstream msg;
      msg << "scene: Dirichlet DoF " << d << " is out of range [0, " << n << ")";
      throw InvalidInputError(msg.str());
    }
    if (k > 0 && d <= dirichlet.dofs[k - 1]) {
      std::ostringstream msg;
      msg << "scene: Dirichlet DoFs must be strictly increasing (" << dirichlet.dofs[k - 1] << " then " << d << ")";
      throw InvalidInputError(msg.str());
    }
    if (!std::isfinite(dirichlet.values(k))) {
      std::ostringstream msg;
      msg << "scene: the Dirichlet value of DoF " << d << " is not finite";
      throw InvalidInputError(msg.str());
    }
  }
  internal::ValidateOptionalTerms(*this);
}

namespace {

// FixNodeAxes, with `function` naming the caller in messages.
void FixAxes(Scene* scene, const std::vector<int>& nodes, const std::vector<int>& axes, const char* function) {
  for (const int a : axes)
    if (a < 0 || a > 2) {
      std::ostringstream msg;
      msg << function << ": axis " << a << " is invalid: must be 0 (x), 1 (y) or 2 (z)";
      throw InvalidInputError(msg.str());
    }
  std::vector<std::pair<int, double>> all;
  for (size_t k = 0; k < scene->dirichlet.dofs.size(); ++k)
    all.emplace_back(scene->dirichlet.dofs[k], scene->dirichlet.values(k));
  for (const int i : nodes) {
    if (i < 0 || i >= scene->mesh.num_vertices()) {
      std::ostringstream msg;
      msg << function << ": node " << i << " is out of range [0, " << scene->mesh.num_vertices() << ")";
      throw InvalidInputError(msg.str());
    }
    for (const int a : axes) all.emplace_back(3 * i + a, scene->mesh.vertices(a, i));
  }
  std::sort(all.begin(), all.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
  all.erase(std::unique(all.begin(), all.end(), [](const auto& p, const auto& q) { return p.first == q.first; }),
            all.end());
  scene->dirichlet.dofs.resize(all.size());
  scene->dirichlet.values.resize(all.size());
  for (size_t k = 0; k < all.size(); ++k) {
    scene->dirichlet.dofs[k] = all[k].first;
    scene->dirichlet.values(k) = all[k].second;
  }
}

}  // namespace

void FixNodeAxes(Scene* scene, const std::vector<int>& nodes, const std::vector<int>& axes) {
  FixAxes(scene, nodes, axes, "FixNodeAxes");
}

void FixNodes(Scene* scene, const std::vector<int>& nodes) { FixAxes(scene, nodes, {0, 1, 2}, "FixNodes"); }

}  // namespace diffpd
