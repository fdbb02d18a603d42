// Per-region materials in the simulator (Scene::material_regions): regions
// equal to the base material change nothing; a region covering every
// element acts as the scene's material; the implicit methods agree on a
// two-region beam; rollout gradients (Backward) and tangents w.r.t. every
// region's E, nu and density match central finite differences for every
// method; SetRegionMaterial validates and is checked by Backward/Tangents.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <random>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"
#include "util/expect_message.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

using testing::MovingStart;
using testing::RandomVector;
using testing::TightOptions;

int StepsFor(Method method) { return method == Method::kSemiImplicit ? 20 : 4; }

std::string MethodName(Method m) {
  std::string name = ToString(m);
  for (char& ch : name)
    if (ch == '-') ch = '_';
  return name;
}

const Method kAllMethods[] = {Method::kSemiImplicit, Method::kNewtonCholesky, Method::kNewtonPcg, Method::kPd,
                              Method::kPdLbfgs};

class RegionMaterialsTest : public ::testing::TestWithParam<Method> {};

TEST_P(RegionMaterialsTest, RegionsEqualToTheBaseMaterialChangeNothing) {
  const Method method = GetParam();
  const Scene plain = testing::SmallBeamScene();
  Scene regions = testing::TwoRegionBeamScene();
  for (MaterialRegion& r : regions.material_regions) r.material = plain.material;
  const SolverOptions options = TightOptions(method);
  Simulator a(plain, options), b(regions, options);
  const int steps = StepsFor(method);
  const Rollout ra = a.Simulate(MovingStart(a), std::vector<StepInput>(steps));
  const Rollout rb = b.Simulate(MovingStart(b), std::vector<StepInput>(steps));
  EXPECT_EQ((a.LumpedMass() - b.LumpedMass()).norm(), 0.0);
  for (int k = 0; k <= steps; ++k) {
    EXPECT_EQ((ra.states[k].x - rb.states[k].x).norm(), 0.0) << "x_" << k;
    EXPECT_EQ((ra.states[k].v - rb.states[k].v).norm(), 0.0) << "v_" << k;
  }
  std::mt19937_64 rng(3);
  LossGradient loss(steps);
  for (int k = 0; k <= steps; ++k) loss.dx[k] = RandomVector(a.num_dofs(), &rng, 1.0);
  const RolloutGradient ga = a.Backward(ra, loss), gb = b.Backward(rb, loss);
  EXPECT_EQ((ga.x0 - gb.x0).norm(), 0.0);
  EXPECT_EQ((ga.v0 - gb.v0).norm(), 0.0);
  ASSERT_EQ(gb.region_materials.size(), 2u);
  EXPECT_TRUE(ga.region_materials.empty());
  // The whole body's parameters move every part together: the parts' sum.
  auto sum = [&](double RolloutGradient::*base, double MaterialComponents::*region) {
    return gb.*base + gb.region_materials[0].*region + gb.region_materials[1].*region;
  };
  EXPECT_NEAR(sum(&RolloutGradient::youngs_modulus, &MaterialComponents::youngs_modulus), ga.youngs_modulus,
              1e-10 * std::abs(ga.youngs_modulus));
  EXPECT_NEAR(sum(&RolloutGradient::poissons_ratio, &MaterialComponents::poissons_ratio), ga.poissons_ratio,
              1e-10 * std::abs(ga.poissons_ratio));
  EXPECT_NEAR(sum(&RolloutGradient::density, &MaterialComponents::density), ga.density, 1e-10 * std::abs(ga.density));
}

TEST_P(RegionMaterialsTest, ARegionCoveringEveryElementActsAsTheSceneMaterial) {
  const Method method = GetParam();
  Scene uniform = testing::SmallBeamScene();
  uniform.material = MaterialParameters{7e4, 0.3, 1.7e3};
  Scene covered = testing::SmallBeamScene();  // base material 2e5, 0.4, 1e3: in no element
  MaterialRegion all;
  for (int e = 0; e < covered.mesh.num_elements(); ++e) all.elements.push_back(e);
  all.material = uniform.material;
  covered.material_regions = {all};
  const SolverOptions options = TightOptions(method);
  Simulator a(uniform, options), b(covered, options);
  const int steps = StepsFor(method);
  const Rollout ra = a.Simulate(MovingStart(a), std::vector<StepInput>(steps));
  const Rollout rb = b.Simulate(MovingStart(b), std::vector<StepInput>(steps));
  EXPECT_LT((a.LumpedMass() - b.LumpedMass()).norm(), 1e-14 * a.LumpedMass().norm());
  const double scale = (ra.states[steps].x - ra.states[0].x).norm();
  EXPECT_LT((ra.states[steps].x - rb.states[steps].x).norm(), 1e-8 * scale);
  LossGradient loss(steps);
  loss.dx[steps] = VectorXd::Ones(a.num_dofs());
  const RolloutGradient ga = a.Backward(ra, loss), gb = b.Backward(rb, loss);
  ASSERT_EQ(gb.region_materials.size(), 1u);
  EXPECT_NEAR(gb.region_materials[0].youngs_modulus, ga.youngs_modulus, 1e-6 * std::abs(ga.youngs_modulus));
  EXPECT_NEAR(gb.region_materials[0].poissons_ratio, ga.poissons_ratio, 1e-6 * std::abs(ga.poissons_ratio));
  EXPECT_NEAR(gb.region_materials[0].density, ga.density, 1e-6 * std::abs(ga.density));
  // The base material has no element: no stiffness or mass derivative.
  EXPECT_EQ(gb.youngs_modulus, 0.0);
  EXPECT_EQ(gb.poissons_ratio, 0.0);
  EXPECT_EQ(gb.density, 0.0);
}

// One scalar parameter of the scene: base (region -1) or region r's field.
struct Parameter {
  int region;
  double MaterialParameters::*field;
  double scale;  // the direction's size: a relative step for E and rho
  const char* name;
};

std::vector<Parameter> AllParameters(const Scene& scene) {
  std::vector<Parameter> out;
  for (int r = -1; r < static_cast<int>(scene.material_regions.size()); ++r) {
    const MaterialParameters& m = r < 0 ? scene.material : scene.material_regions[r].material;
    out.push_back({r, &MaterialParameters::youngs_modulus, m.youngs_modulus, "E"});
    out.push_back({r, &MaterialParameters::poissons_ratio, 1.0, "nu"});
    out.push_back({r, &MaterialParameters::density, m.density, "rho"});
  }
  return out;
}

Scene Moved(const Scene& scene, const Parameter& p, double eps) {
  Scene s = scene;
  MaterialParameters& m = p.region < 0 ? s.material : s.material_regions[p.region].material;
  m.*(p.field) += eps * p.scale;
  return s;
}

InputDirection DirectionOf(const Parameter& p, int num_regions) {
  InputDirection d;
  if (p.region < 0) {
    if (p.field == &MaterialParameters::youngs_modulus) d = InputDirection::YoungsModulus();
    if (p.field == &MaterialParameters::poissons_ratio) d = InputDirection::PoissonsRatio();
    if (p.field == &MaterialParameters::density) d = InputDirection::Density();
  } else {
    if (p.field == &MaterialParameters::youngs_modulus) d = InputDirection::RegionYoungsModulus(p.region, num_regions);
    if (p.field == &MaterialParameters::poissons_ratio) d = InputDirection::RegionPoissonsRatio(p.region, num_regions);
    if (p.field == &MaterialParameters::density) d = InputDirection::RegionDensity(p.region, num_regions);
  }
  // Scale the unit direction.
  d.youngs_modulus *= p.scale;
  d.poissons_ratio *= p.scale;
  d.density *= p.scale;
  for (MaterialComponents& c : d.region_materials) {
    c.youngs_modulus *= p.scale;
    c.poissons_ratio *= p.scale;
    c.density *= p.scale;
  }
  return d;
}

double GradientAlong(const RolloutGradient& g, const Parameter& p) {
  MaterialComponents c;
  if (p.region < 0) {
    c.youngs_modulus = g.youngs_modulus;
    c.poissons_ratio = g.poissons_ratio;
    c.density = g.density;
  } else {
    c = g.region_materials[p.region];
  }
  const double value = p.field == &MaterialParameters::youngs_modulus   ? c.youngs_modulus
                       : p.field == &MaterialParameters::poissons_ratio ? c.poissons_ratio
                                                                        : c.density;
  return value * p.scale;
}

struct Case {
  Method method;
  bool tets;
  bool damping;  // linear damping: Backward only (tangents reject state forces)
};

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  return MethodName(info.param.method) + (info.param.tets ? "_tet" : "_hex") + (info.param.damping ? "_damped" : "");
}

class RegionDerivativeTest : public ::testing::TestWithParam<Case> {};

// For every parameter (base and per region E, nu, rho): the adjoint gradient
// of a random linear loss and the tangent of every state vs central
// differences of whole rollouts, and the tangents vs the adjoint.
TEST_P(RegionDerivativeTest, BackwardAndTangentsMatchCentralFiniteDifferences) {
  const Case c = GetParam();
  Scene scene = testing::TwoRegionBeamScene(c.tets);
  if (c.damping) scene.linear_damping = 3.0;
  SolverOptions options = TightOptions(c.method);
  // The tip's nu moves the states little (tangents ~1e-4 m): the forward
  // solves must be converged far below that for differences to resolve it.
  options.abs_tolerance = 1e-12;
  Simulator sim(scene, options);
  const int n = sim.num_dofs();
  const int steps = StepsFor(c.method);
  const State start = MovingStart(sim);
  const Rollout rollout = sim.Simulate(start, std::vector<StepInput>(steps));
  ASSERT_EQ(rollout.region_materials.size(), 2u);
  std::mt19937_64 rng(5);
  LossGradient loss(steps);
  for (int k = 1; k <= steps; ++k) {
    loss.dx[k] = RandomVector(n, &rng, 1.0);
    loss.dv[k] = RandomVector(n, &rng, 0.01);
  }
  auto loss_of = [&](const Rollout& r) {
    double l = 0;
    for (int k = 1; k <= steps; ++k) l += loss.dx[k].dot(r.states[k].x) + loss.dv[k].dot(r.states[k].v);
    return l;
  };
  const RolloutGradient g = sim.Backward(rollout, loss);
  ASSERT_EQ(g.region_materials.size(), 2u);
  const std::vector<Parameter> params = AllParameters(scene);
  std::vector<InputDirection> dirs;
  for (const Parameter& p : params) dirs.push_back(DirectionOf(p, 2));
  TangentRollout t;
  if (!c.damping) t = sim.Tangents(rollout, dirs);
  // The step rule for rollouts solved to rel_tolerance along directions
  // scaled to their parameters (input scale 1): eps = cbrt(1e-12) = 1e-4.
  const double eps = testing::CentralDifferenceStep(options.rel_tolerance, 1.0);
  for (size_t j = 0; j < params.size(); ++j) {
    const Parameter& p = params[j];
    const std::string what = std::string(p.name) + " of region " + std::to_string(p.region);
    Simulator plus_sim(Moved(scene, p, eps), options), minus_sim(Moved(scene, p, -eps), options);
    const Rollout plus = plus_sim.Simulate(start, std::vector<StepInput>(steps));
    const Rollout minus = minus_sim.Simulate(start, std::vector<StepInput>(steps));
    const double adjoint = GradientAlong(g, p);
    // The differences carry the forward solves' stopping points: measured
    // ~5e-11 here (two equally valid preconditioners move fd by that much),
    // hence the test's own floor 2e-10; the smallest gradient (the tip's nu)
    // is 4e-6, so a wrong one still errs far beyond it.
    testing::DifferenceOptions loss_check;
    loss_check.noise = options.rel_tolerance;
    loss_check.rtol = 1e-5;
    loss_check.floor = 2e-10;
    EXPECT_TRUE(
        testing::Passes(testing::CompareCentralDifference(loss_of(plus), loss_of(minus), eps, adjoint, loss_check)))
        << what;
    EXPECT_NE(adjoint, 0.0) << what;
    if (c.damping) continue;
    // The differences carry the forward solves' own error (~1e-14 m at
    // these tolerances) over 2 eps: ~1e-10 m, 1e-6 of the smallest
    // tangents (the tip's nu, ~1e-4 m); a wrong tangent errs by O(1). So
    // relative to the direction's largest state tangent, no floor.
    testing::DifferenceOptions x_check;
    x_check.noise = options.rel_tolerance;
    x_check.rtol = 3e-6;
    x_check.floor = 0;
    for (int k = 1; k <= steps; ++k)
      x_check.derivative_scale = std::max(x_check.derivative_scale, t.dx[k].col(j).norm());
    ASSERT_GT(x_check.derivative_scale, 0.0) << what;
    double forward = 0;
    for (int k = 1; k <= steps; ++k) {
      EXPECT_TRUE(testing::Passes(
          testing::CompareCentralDifference(plus.states[k].x, minus.states[k].x, eps, t.dx[k].col(j), x_check)))
          << what << " x_" << k;
      forward += loss.dx[k].dot(t.dx[k].col(j)) + loss.dv[k].dot(t.dv[k].col(j));
    }
    EXPECT_NEAR(forward, adjoint, 1e-8 * std::abs(adjoint)) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(AllMethods, RegionMaterialsTest, ::testing::ValuesIn(kAllMethods),
                         [](const ::testing::TestParamInfo<Method>& info) { return MethodName(info.param); });
// PD is checked on tets (hexes need very many PD iterations for tight
// forward solves), like the uniform-material tangent tests.
INSTANTIATE_TEST_SUITE_P(AllMethods, RegionDerivativeTest,
                         ::testing::Values(Case{Method::kSemiImplicit, false, false},
                                           Case{Method::kNewtonCholesky, false, false},
                                           Case{Method::kNewtonPcg, false, false}, Case{Method::kPd, true, false},
                                           Case{Method::kPdLbfgs, false, false},
                                           Case{Method::kSemiImplicit, false, true},
                                           Case{Method::kNewtonCholesky, false, true}),
                         CaseName);

TEST(RegionMaterialsTest, ImplicitMethodsAgreeOnATwoRegionBeam) {
  const Scene scene = testing::TwoRegionBeamScene();
  std::vector<VectorXd> finals;
  for (Method m : {Method::kNewtonCholesky, Method::kNewtonPcg, Method::kPd, Method::kPdLbfgs}) {
    SolverOptions options = TightOptions(m);
    options.rel_tolerance = 1e-10;
    Simulator sim(scene, options);
    finals.push_back(sim.Simulate(sim.RestState(), std::vector<StepInput>(5)).states.back().x);
  }
  const VectorXd rest = Eigen::Map<const VectorXd>(scene.mesh.vertices.data(), scene.mesh.num_dofs());
  const double motion = (finals[0] - rest).norm();
  for (size_t i = 1; i < finals.size(); ++i) EXPECT_LT((finals[i] - finals[0]).norm(), 1e-6 * motion) << i;
}

TEST(RegionMaterialsTest, ASofterRegionSagsMore) {
  Scene scene = testing::TwoRegionBeamScene();
  for (MaterialRegion& r : scene.material_regions) r.material = scene.material;
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  Simulator sim(scene, options);
  const VectorXd stiff = sim.SolveQuasiStatic(sim.RestState().x, StepInput());
  MaterialParameters soft = scene.material;
  soft.youngs_modulus /= 5;
  sim.SetRegionMaterial(0, soft);
  const VectorXd softer = sim.SolveQuasiStatic(sim.RestState().x, StepInput());
  const VectorXd rest = sim.RestState().x;
  EXPECT_LT(softer.minCoeff() - rest.minCoeff(), 0.0);
  EXPECT_GT((rest - softer).cwiseAbs().maxCoeff(), 1.5 * (rest - stiff).cwiseAbs().maxCoeff());
}

TEST(RegionMaterialsTest, SetRegionMaterialValidatesAndRolloutsRecordTheRegions) {
  const Scene scene = testing::TwoRegionBeamScene();
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  Simulator sim(scene, options);
  auto message = [&](int region, const MaterialParameters& m) {
    return testing::MessageOf<InvalidInputError>([&] { sim.SetRegionMaterial(region, m); });
  };
  EXPECT_EQ(message(2, MaterialParameters()), "SetRegionMaterial: region 2 is out of range [0, 2)");
  EXPECT_EQ(message(-1, MaterialParameters()), "SetRegionMaterial: region -1 is out of range [0, 2)");
  MaterialParameters bad;
  bad.youngs_modulus = -1;
  EXPECT_EQ(message(0, bad),
            "SetRegionMaterial: region 0: youngs_modulus = -1 is invalid: must be finite and > 0 (Pa)");
  EXPECT_EQ(sim.scene().material_regions[0].material.youngs_modulus, scene.material_regions[0].material.youngs_modulus);
  const Rollout r = sim.Simulate(sim.RestState(), std::vector<StepInput>(2));
  ASSERT_EQ(r.region_materials.size(), 2u);
  EXPECT_EQ(r.region_materials[1].density, scene.material_regions[1].material.density);
  MaterialParameters other = scene.material_regions[1].material;
  other.poissons_ratio = 0.25;
  EXPECT_NO_THROW(sim.SetRegionMaterial(1, other));
  LossGradient loss(2);
  EXPECT_THROW(sim.Backward(r, loss), InvalidInputError);
  EXPECT_THROW(sim.Tangents(r, {InputDirection::YoungsModulus()}), InvalidInputError);
  sim.SetRegionMaterial(1, scene.material_regions[1].material);
  EXPECT_NO_THROW(sim.Backward(r, loss));
  // Directions must have no or one entry per region.
  InputDirection wrong;
  wrong.region_materials.resize(3);
  EXPECT_THROW_MESSAGE(
      sim.Tangents(r, {wrong}), InvalidInputError,
      "Tangents: direction 0 has region_materials for 3 regions, expected 0 or 2 (one per material region)");
  EXPECT_THROW_MESSAGE(InputDirection::RegionDensity(2, 2), InvalidInputError,
                       "InputDirection: region 2 is out of range [0, 2)");
}

}  // namespace
}  // namespace diffpd
