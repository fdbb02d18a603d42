// Material regions of a scene (internal): validation and the element ->
// material "part" map the simulator works with.
//
// Parts number the materials of a body: part 0 is the base material
// (Scene::material, every element in no region), part r + 1 is
// Scene::material_regions[r]. A scene without regions has one part.
#pragma once

#include <vector>

#include "diffpd/scene.h"

namespace diffpd::internal {

// Throws InvalidInputError with the messages listed at Scene::Validate for
// the regions of `scene`, whose mesh must be valid.
void ValidateMaterialRegions(const Scene& scene);

// Part of every element (num_elements entries in [0, num_parts)), or empty
// when the scene has no material region. The scene must be valid.
std::vector<int> PartOfElement(const Scene& scene);

// The material of every part: {scene.material, region 0's, region 1's, ...}.
std::vector<MaterialParameters> PartMaterials(const Scene& scene);

}  // namespace diffpd::internal
