// Scenes (diffpd/scene.h): FixNodes / FixNodeAxes pin the right DoFs and
// refuse bad nodes and axes, leaving the scene unchanged; Scene::Validate
// refuses energies that are no ElasticEnergy.
#include "diffpd/scene.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "diffpd/error.h"
#include "util/expect_message.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

Scene Cube() {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(1, 1, 1, 0.1, 0.2, 0.3);
  return scene;
}

TEST(SceneTest, FixNodeAxesPinsThoseAxesAtRestMergedWithTheExistingOnes) {
  Scene scene = Cube();
  FixNodeAxes(&scene, {7, 1}, {2, 0});
  FixNodes(&scene, {1});
  EXPECT_EQ(scene.dirichlet.dofs, (std::vector<int>{3, 4, 5, 21, 23}));
  ASSERT_EQ(scene.dirichlet.values.size(), 5);
  EXPECT_EQ(scene.dirichlet.values(2), 0.3);  // node 1 is (0, 0, 0.3)
  EXPECT_EQ(scene.dirichlet.values(3), 0.1);  // node 7 is (0.1, 0.2, 0.3)
  EXPECT_NO_THROW(scene.Validate());
}

// A call that must refuse its input, and the exact message.
struct Refusal {
  std::function<void(Scene*)> call;
  std::string message;
};

TEST(SceneTest, FixNodeAxesRefusesBadAxesAndNodesLeavingTheSceneUnchanged) {
  const Refusal cases[] = {
      {[](Scene* s) { FixNodeAxes(s, {0}, {5}); }, "FixNodeAxes: axis 5 is invalid: must be 0 (x), 1 (y) or 2 (z)"},
      {[](Scene* s) {
         FixNodeAxes(s, {0}, {0, -1});
       },
       "FixNodeAxes: axis -1 is invalid: must be 0 (x), 1 (y) or 2 (z)"},
      {[](Scene* s) {
         FixNodeAxes(s, {3, -1}, {1});
       },
       "FixNodeAxes: node -1 is out of range [0, 8)"},
      {[](Scene* s) { FixNodeAxes(s, {8}, {1}); }, "FixNodeAxes: node 8 is out of range [0, 8)"},
      {[](Scene* s) {
         FixNodes(s, {2, 99});
       },
       "FixNodes: node 99 is out of range [0, 8)"},
  };
  for (const Refusal& c : cases) {
    Scene scene = Cube();
    FixNodes(&scene, {0});
    EXPECT_THROW_MESSAGE(c.call(&scene), InvalidInputError, c.message);
    EXPECT_EQ(scene.dirichlet.dofs, (std::vector<int>{0, 1, 2}));
  }
}

TEST(SceneTest, ValidateRefusesAnIntegerCastToElasticEnergy) {
  for (const int value : {5, -1, 100}) {
    Scene scene = Cube();
    scene.energies = {ElasticEnergy::kPdCorotated, static_cast<ElasticEnergy>(value)};
    EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                         "scene: energies[1] = " + std::to_string(value) +
                             " is invalid: must be an ElasticEnergy, 0 (linear) to 4 (pd-volume)");
  }
}

}  // namespace
}  // namespace diffpd
