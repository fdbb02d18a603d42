#include "diffpd/solvers/core/material_block.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

double& Field(MaterialParameters* m, MaterialField f) {
  switch (f) {
    case MaterialField::kYoungsModulus:
      return m->youngs_modulus;
    case MaterialField::kPoissonsRatio:
      return m->poissons_ratio;
    case MaterialField::kDensity:
      return m->density;
  }
  DIFFPD_CHECK(false, "unknown MaterialField " << static_cast<int>(f));
}

double& Field(MaterialComponents* c, MaterialField f) {
  switch (f) {
    case MaterialField::kYoungsModulus:
      return c->youngs_modulus;
    case MaterialField::kPoissonsRatio:
      return c->poissons_ratio;
    case MaterialField::kDensity:
      return c->density;
  }
  DIFFPD_CHECK(false, "unknown MaterialField " << static_cast<int>(f));
}

double Field(const MaterialComponents& c, MaterialField f) {
  MaterialComponents copy = c;
  return Field(&copy, f);
}

void CheckRegion(int entry, int region, const Scene& scene) {
  const int regions = static_cast<int>(scene.material_regions.size());
  if (region != kBaseMaterial && (region < 0 || region >= regions)) {
    std::ostringstream msg;
    msg << "material: entry " << entry << ": region " << region << " is out of range [0, " << regions << ")";
    throw InvalidInputError(msg.str());
  }
}

}  // namespace

const char* ToString(MaterialField field) {
  switch (field) {
    case MaterialField::kYoungsModulus:
      return "youngs_modulus";
    case MaterialField::kPoissonsRatio:
      return "poissons_ratio";
    case MaterialField::kDensity:
      return "density";
  }
  return "unknown";
}

MaterialBlock::MaterialBlock(std::vector<Entry> entries, const Scene& scene)
    : ParameterBlock(static_cast<int>(entries.size())), entries_(std::move(entries)) {
  if (entries_.empty()) throw InvalidInputError("material: no parameter");
  VectorXd initial(entries_.size());
  for (size_t i = 0; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    const int index = static_cast<int>(i);
    if (!(std::isfinite(e.scale) && e.scale > 0)) {
      std::ostringstream msg;
      msg << "material: entry " << i << ": scale = " << e.scale << " is invalid: must be finite and > 0";
      throw InvalidInputError(msg.str());
    }
    CheckRegion(index, e.region, scene);
    for (size_t j = 0; j < i; ++j)
      if (entries_[j].field == e.field && entries_[j].region == e.region) {
        std::ostringstream msg;
        msg << "material: entry " << i << " lists " << ToString(e.field) << " of ";
        if (e.region == kBaseMaterial)
          msg << "the base material";
        else
          msg << "region " << e.region;
        msg << " again";
        throw InvalidInputError(msg.str());
      }
    MaterialParameters m = e.region == kBaseMaterial ? scene.material : scene.material_regions[e.region].material;
    initial(index) = Field(&m, e.field) / e.scale;
  }
  SetInitial(initial);
}

void MaterialBlock::CheckFits(const Scene& scene, int num_steps) const {
  for (size_t i = 0; i < entries_.size(); ++i) CheckRegion(static_cast<int>(i), entries_[i].region, scene);
}

void MaterialBlock::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  for (size_t i = 0; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    MaterialParameters* m = e.region == kBaseMaterial ? &setup->material : &setup->region_materials[e.region];
    Field(m, e.field) = values(i) * e.scale;
  }
}

void MaterialBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                             Eigen::Ref<VectorXd> out) const {
  MaterialComponents base;
  base.youngs_modulus = grad.youngs_modulus;
  base.poissons_ratio = grad.poissons_ratio;
  base.density = grad.density;
  for (size_t i = 0; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    const MaterialComponents& g = e.region == kBaseMaterial ? base : grad.region_materials[e.region];
    out(i) = Field(g, e.field) * e.scale;
  }
}

void MaterialBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                                InputDirection* direction) const {
  const Entry& e = entries_[j];
  if (e.region == kBaseMaterial) {
    switch (e.field) {
      case MaterialField::kYoungsModulus:
        direction->youngs_modulus += e.scale;
        break;
      case MaterialField::kPoissonsRatio:
        direction->poissons_ratio += e.scale;
        break;
      case MaterialField::kDensity:
        direction->density += e.scale;
        break;
    }
  } else {
    Field(&direction->region_materials[e.region], e.field) += e.scale;
  }
}

}  // namespace diffpd::solvers
