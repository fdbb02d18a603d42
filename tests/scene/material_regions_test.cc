// Material regions of a scene: every validation message of Scene::Validate
// for regions, and the element -> part map the simulator uses.
#include <gtest/gtest.h>

#include <string>

#include "diffpd/error.h"
#include "scene/material_regions.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

std::string ValidationMessage(const Scene& scene) {
  return testing::MessageOf<InvalidInputError>([&] { scene.Validate(); });
}

Scene WithRegions(std::vector<MaterialRegion> regions) {
  Scene scene = testing::SmallBeamScene();  // 16 hexes
  scene.material_regions = std::move(regions);
  return scene;
}

TEST(MaterialRegionsTest, ValidScenesPass) {
  EXPECT_NO_THROW(testing::TwoRegionBeamScene().Validate());
  EXPECT_NO_THROW(testing::TwoRegionBeamScene(/*tets=*/true).Validate());
  EXPECT_NO_THROW(WithRegions({{{15, 0, 7}, MaterialParameters()}}).Validate());
}

TEST(MaterialRegionsTest, EveryInvalidRegionIsNamedPrecisely) {
  const MaterialParameters ok;
  EXPECT_EQ(ValidationMessage(WithRegions({{{0}, ok}, {{}, ok}})), "scene: material region 1 has no element");
  EXPECT_EQ(ValidationMessage(WithRegions({{{0}, ok}, {{3, 16}, ok}})),
            "scene: material region 1 lists element 16, out of range [0, 16)");
  EXPECT_EQ(ValidationMessage(WithRegions({{{-1}, ok}})),
            "scene: material region 0 lists element -1, out of range [0, 16)");
  EXPECT_EQ(ValidationMessage(WithRegions({{{0}, ok}, {{4, 5, 4}, ok}})),
            "scene: material region 1 lists element 4 twice");
  EXPECT_EQ(ValidationMessage(WithRegions({{{1, 5}, ok}, {{2}, ok}, {{3, 5}, ok}})),
            "scene: element 5 is in material regions 0 and 2");
  MaterialParameters bad_e = ok;
  bad_e.youngs_modulus = 0;
  EXPECT_EQ(ValidationMessage(WithRegions({{{0}, ok}, {{1}, bad_e}})),
            "scene: material region 1: youngs_modulus = 0 is invalid: must be finite and > 0 (Pa)");
  MaterialParameters bad_nu = ok;
  bad_nu.poissons_ratio = 0.5;
  EXPECT_EQ(ValidationMessage(WithRegions({{{0}, bad_nu}})),
            "scene: material region 0: poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");
  MaterialParameters bad_rho = ok;
  bad_rho.density = -2;
  EXPECT_EQ(ValidationMessage(WithRegions({{{0}, bad_rho}})),
            "scene: material region 0: density = -2 is invalid: must be finite and > 0 (kg/m^3)");
}

TEST(MaterialRegionsTest, PartsNumberTheBaseMaterialZeroAndRegionRAsRPlusOne) {
  const Scene scene = testing::TwoRegionBeamScene();
  const std::vector<int> part = internal::PartOfElement(scene);
  ASSERT_EQ(static_cast<int>(part.size()), scene.mesh.num_elements());
  std::vector<int> count(3, 0);
  for (const int p : part) ++count[p];
  EXPECT_GT(count[0], 0);
  EXPECT_EQ(count[1], static_cast<int>(scene.material_regions[0].elements.size()));
  EXPECT_EQ(count[2], static_cast<int>(scene.material_regions[1].elements.size()));
  for (const int e : scene.material_regions[1].elements) EXPECT_EQ(part[e], 2);
  EXPECT_TRUE(internal::PartOfElement(testing::SmallBeamScene()).empty());
  const std::vector<MaterialParameters> materials = internal::PartMaterials(scene);
  ASSERT_EQ(materials.size(), 3u);
  EXPECT_EQ(materials[2].youngs_modulus, scene.material_regions[1].material.youngs_modulus);
}

}  // namespace
}  // namespace diffpd
