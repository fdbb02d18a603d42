#include "scene/material_regions.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {

void ValidateMaterialRegions(const Scene& scene) {
  const int m = scene.mesh.num_elements();
  std::vector<int> region_of(m, -1);
  for (size_t r = 0; r < scene.material_regions.size(); ++r) {
    const MaterialRegion& region = scene.material_regions[r];
    if (region.elements.empty()) {
      std::ostringstream msg;
      msg << "scene: material region " << r << " has no element";
      throw InvalidInputError(msg.str());
    }
    for (const int e : region.elements) {
      if (e < 0 || e >= m) {
        std::ostringstream msg;
        msg << "scene: material region " << r << " lists element " << e << ", out of range [0, " << m << ")";
        throw InvalidInputError(msg.str());
      }
      if (region_of[e] == static_cast<int>(r)) {
        std::ostringstream msg;
        msg << "scene: material region " << r << " lists element " << e << " twice";
        throw InvalidInputError(msg.str());
      }
      if (region_of[e] >= 0) {
        std::ostringstream msg;
        msg << "scene: element " << e << " is in material regions " << region_of[e] << " and " << r;
        throw InvalidInputError(msg.str());
      }
      region_of[e] = static_cast<int>(r);
    }
    try {
      region.material.Validate();
    } catch (const InvalidInputError& e) {
      std::ostringstream msg;
      msg << "scene: material region " << r << ": " << e.what();
      throw InvalidInputError(msg.str());
    }
  }
}

std::vector<int> PartOfElement(const Scene& scene) {
  if (scene.material_regions.empty()) return {};
  std::vector<int> part(scene.mesh.num_elements(), 0);
  for (size_t r = 0; r < scene.material_regions.size(); ++r)
    for (const int e : scene.material_regions[r].elements) part[e] = static_cast<int>(r) + 1;
  return part;
}

std::vector<MaterialParameters> PartMaterials(const Scene& scene) {
  std::vector<MaterialParameters> out = {scene.material};
  for (const MaterialRegion& region : scene.material_regions) out.push_back(region.material);
  return out;
}

}  // namespace diffpd::internal
