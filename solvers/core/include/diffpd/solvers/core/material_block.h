// Material parameters as optimisation parameters: Young's modulus, Poisson's
// ratio and density of the base material (Scene::material) and of material
// regions (Scene::material_regions), each divided by a scale so that the
// optimiser may see numbers near 1: parameter = value / scale.
//
//   MaterialBlock({MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio}, scene);    // {E, nu}
//   MaterialBlock({{MaterialField::kYoungsModulus, 0, 1e5}}, scene);   // region 0's E in units of 1e5 Pa
#pragma once

#include <string>
#include <vector>

#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::solvers {

enum class MaterialField { kYoungsModulus, kPoissonsRatio, kDensity };
// "youngs_modulus", "poissons_ratio", "density".
const char* ToString(MaterialField field);

// MaterialBlock::Entry::region of the base material.
inline constexpr int kBaseMaterial = -1;

class MaterialBlock : public ParameterBlock {
 public:
  struct Entry {
    // Implicit from a field: the base material's, scale 1.
    Entry(MaterialField field = MaterialField::kYoungsModulus, int region = kBaseMaterial, double scale = 1)
        : field(field), region(region), scale(scale) {}
    MaterialField field;
    int region;    // kBaseMaterial or an index into Scene::material_regions
    double scale;  // units of the value per parameter unit (Pa, 1, kg/m^3), finite and > 0
  };
  // Starting values: `scene`'s values / scale. Throws InvalidInputError:
  //   "material: no parameter",
  //   "material: entry 1: scale = 0 is invalid: must be finite and > 0",
  //   "material: entry 1: region 2 is out of range [0, 2)",
  //   "material: entry 2 lists youngs_modulus of region 1 again",
  //   "material: entry 1 lists density of the base material again".
  MaterialBlock(std::vector<Entry> entries, const Scene& scene);
  std::string name() const override { return "material"; }
  const std::vector<Entry>& entries() const { return entries_; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  // Overwrites the fields of setup->material and setup->region_materials.
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                   InputDirection* direction) const override;

 private:
  std::vector<Entry> entries_;
};

}  // namespace diffpd::solvers
