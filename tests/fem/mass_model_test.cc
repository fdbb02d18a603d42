// Lumped mass with a density per material part (fem/mass_model.h).
#include <gtest/gtest.h>

#include "fem/fem_model.h"
#include "fem/mass_model.h"
#include "scene/material_regions.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

TEST(MassModelTest, PartsSplitTheBodyMassAndUniformDensitiesTakeTheSinglePartArithmetic) {
  for (const bool tets : {false, true}) {
    const Scene scene = testing::TwoRegionBeamScene(tets);
    internal::FemModel fem(scene.mesh);
    const std::vector<int> part = internal::PartOfElement(scene);
    internal::MassModel mass(fem, part, 3), single(fem, {}, 1);
    ASSERT_EQ(mass.num_parts(), 3);
    const VectorXd total = mass.part_unit_mass(0) + mass.part_unit_mass(1) + mass.part_unit_mass(2);
    EXPECT_LT((total - mass.unit_mass()).norm(), 1e-15 * mass.unit_mass().norm());
    for (int p = 0; p < 3; ++p) EXPECT_GT(mass.part_unit_mass(p).sum(), 0.0);
    // The whole mesh's mass: volume x density.
    double volume = 0;
    for (int e = 0; e < fem.num_elements(); ++e) volume += fem.element_volume(e);
    EXPECT_NEAR(mass.unit_mass().sum(), 3 * volume, 1e-12 * volume);
    mass.SetDensities({1e3, 1e3, 1e3});
    single.SetDensities({1e3});
    EXPECT_EQ((mass.mass() - single.mass()).norm(), 0.0);
    mass.SetDensities({1e3, 2e3, 0.5e3});
    const VectorXd expected =
        1e3 * mass.part_unit_mass(0) + 2e3 * mass.part_unit_mass(1) + 0.5e3 * mass.part_unit_mass(2);
    EXPECT_LT((mass.mass() - expected).norm(), 1e-15 * expected.norm());
    // Direction and gradient are adjoint: g . dM(drho) = dL/drho . drho.
    const VectorXd drho = Eigen::Vector3d(0.3, -1.0, 2.0);
    const VectorXd g = VectorXd::LinSpaced(mass.mass().size(), -1, 1);
    EXPECT_NEAR(g.dot(mass.Direction(drho)), mass.DensityGradient(g).dot(drho), 1e-12 * g.norm());
  }
}

}  // namespace
}  // namespace diffpd
