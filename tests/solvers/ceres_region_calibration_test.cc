// Per-region material parameters in the Ceres calibration adapters
// (CalibrationSetup::fitted_regions): ceres::GradientChecker on the
// MarkerCostFunction with base and region parameters in the material block,
// forward- and reverse-mode Jacobians in agreement, the block's layout and
// validation messages, and noise-free recovery of a stiff/soft cantilever's
// two Young's moduli and Poisson's ratios.
#include <gtest/gtest.h>

#include <random>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>

#include "ceres_calibration_fixture.h"
#include "diffpd/error.h"
#include "diffpd/solvers/coordinate_manifold.h"
#include "diffpd/solvers/marker_cost_function.h"

namespace diffpd::solvers {
namespace {

// The two-region beam (base, soft middle, stiff tip) with base E, nu, the
// middle's E and nu, and the tip's density in the material block.
CalibrationSetup ThreePartSetup(Method method, bool tets, JacobianMode mode) {
  CalibrationSetup setup = testing::SyntheticSetupFromScene(testing::TwoRegionBeamScene(tets), method, 6);
  setup.fitted = {MaterialParameter::kYoungsModulus, MaterialParameter::kPoissonsRatio};
  setup.fitted_regions = {
      {0, MaterialParameter::kYoungsModulus}, {0, MaterialParameter::kPoissonsRatio}, {1, MaterialParameter::kDensity}};
  setup.jacobian = mode;
  return setup;
}

struct CheckCase {
  Method method;
  bool tets;
  JacobianMode mode;
};

std::string CheckCaseName(const ::testing::TestParamInfo<CheckCase>& info) {
  std::string name = ToString(info.param.method);
  for (char& ch : name)
    if (ch == '-') ch = '_';
  name += info.param.tets ? "_tet" : "_hex";
  return name + (info.param.mode == JacobianMode::kForward ? "_forward" : "_reverse");
}

class RegionCostFunctionCheckTest : public ::testing::TestWithParam<CheckCase> {};

TEST_P(RegionCostFunctionCheckTest, GradientCheckerAcceptsRandomRegionParameters) {
  const CheckCase c = GetParam();
  CalibrationModel model(ThreePartSetup(c.method, c.tets, c.mode));
  MarkerCostFunction cost(&model);
  ASSERT_EQ(model.parameter_block_sizes(), std::vector<int>{5});
  const CoordinateManifold manifold({CoordinateMap::Log(), CoordinateMap::Logit(0, 0.5), CoordinateMap::Log(),
                                     CoordinateMap::Logit(0, 0.5), CoordinateMap::Log()});
  std::vector<const ceres::Manifold*> manifolds = {&manifold};
  ceres::NumericDiffOptions numeric;
  numeric.relative_step_size = 1e-5;
  numeric.ridders_relative_initial_step_size = 1e-3;
  ceres::GradientChecker checker(&cost, &manifolds, numeric);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  // Ceres judges each entry relative to itself: an entry 1e-3 of the
  // Jacobian's scale carries the iterative solves' absolute error (2-8e-10
  // here) as a relative error of ~1e-6 for PD-LBFGS (measured 1.8e-6 on
  // d r_3 / d nu, the others below 3e-7); a wrong derivative errs by O(1).
  const double precision = c.method == Method::kPd ? 5e-5 : c.method == Method::kPdLbfgs ? 1e-5 : 1e-6;
  std::vector<double> material = {1e5 + 3e5 * u(rng), 0.25 + 0.2 * u(rng), 2e4 + 8e4 * u(rng), 0.25 + 0.2 * u(rng),
                                  600 + 800 * u(rng)};
  double* blocks[1] = {material.data()};
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks, precision, &results))
      << results.error_log << "\nlast model error: " << model.statistics().last_error;
  EXPECT_LT(results.maximum_relative_error, precision);
}

INSTANTIATE_TEST_SUITE_P(MethodsAndModes, RegionCostFunctionCheckTest,
                         ::testing::Values(CheckCase{Method::kNewtonCholesky, false, JacobianMode::kForward},
                                           CheckCase{Method::kNewtonCholesky, false, JacobianMode::kReverse},
                                           CheckCase{Method::kPdLbfgs, true, JacobianMode::kForward},
                                           CheckCase{Method::kPdLbfgs, false, JacobianMode::kReverse}),
                         CheckCaseName);

TEST(RegionCalibrationTest, ForwardAndReverseJacobiansAgree) {
  for (Method method : {Method::kNewtonCholesky, Method::kPdLbfgs, Method::kSemiImplicit}) {
    // Semi-implicit: the motion from an implicit truth (explicit Euler at the
    // truth's h = 0.01 s tears the beam apart), then a small step.
    CalibrationSetup fwd = ThreePartSetup(method == Method::kSemiImplicit ? Method::kNewtonCholesky : method, false,
                                          JacobianMode::kForward);
    if (method == Method::kSemiImplicit) {
      fwd.solver.method = method;
      fwd.solver.time_step = 1e-3;
      fwd.num_steps = 60;
    }
    CalibrationSetup rev = fwd;
    rev.jacobian = JacobianMode::kReverse;
    rev.input_parameters = fwd.input_parameters = std::make_shared<LinearInputParameters>(
        LinearInputParameters::UniformInitialVelocity(fwd.scene.mesh.num_vertices()));
    CalibrationModel a(fwd), b(rev);
    std::vector<double> material = {1.7e5, 0.37, 6e4, 0.32, 900};
    std::vector<double> velocity = {0.01, -0.02, 0.03};
    const double* blocks[2] = {material.data(), velocity.data()};
    ASSERT_TRUE(a.Evaluate(blocks, true)) << a.statistics().last_error;
    ASSERT_TRUE(b.Evaluate(blocks, true)) << b.statistics().last_error;
    for (int blk = 0; blk < 2; ++blk) {
      const double scale = a.jacobian(blk).norm();
      ASSERT_GT(scale, 0.0);
      EXPECT_LT((a.jacobian(blk) - b.jacobian(blk)).norm(), 1e-8 * scale) << ToString(method) << " block " << blk;
      for (int col = 0; col < a.jacobian(blk).cols(); ++col)
        EXPECT_GT(a.jacobian(blk).col(col).norm(), 0.0) << ToString(method) << " block " << blk << " column " << col;
    }
  }
}

TEST(RegionCalibrationTest, TheMaterialBlockListsFittedThenFittedRegions) {
  CalibrationSetup setup = ThreePartSetup(Method::kNewtonCholesky, false, JacobianMode::kForward);
  const Scene& scene = setup.scene;
  CalibrationModel model(setup);
  double block[5];
  model.InitialMaterialBlock(block);
  EXPECT_EQ(block[0], scene.material.youngs_modulus);
  EXPECT_EQ(block[1], scene.material.poissons_ratio);
  EXPECT_EQ(block[2], scene.material_regions[0].material.youngs_modulus);
  EXPECT_EQ(block[3], scene.material_regions[0].material.poissons_ratio);
  EXPECT_EQ(block[4], scene.material_regions[1].material.density);
  const double values[5] = {1, 0.1, 2, 0.2, 3};
  EXPECT_EQ(model.MaterialAt(values).youngs_modulus, 1);
  EXPECT_EQ(model.MaterialAt(values).density, scene.material.density);
  const MaterialParameters r0 = model.RegionMaterialAt(values, 0), r1 = model.RegionMaterialAt(values, 1);
  EXPECT_EQ(r0.youngs_modulus, 2);
  EXPECT_EQ(r0.poissons_ratio, 0.2);
  EXPECT_EQ(r0.density, scene.material_regions[0].material.density);
  EXPECT_EQ(r1.density, 3);
  EXPECT_EQ(r1.youngs_modulus, scene.material_regions[1].material.youngs_modulus);
  EXPECT_THROW(model.RegionMaterialAt(values, 2), InvalidInputError);
  // Region parameters alone make a material block.
  setup.fitted.clear();
  setup.fitted_regions = {{1, MaterialParameter::kYoungsModulus}};
  EXPECT_EQ(CalibrationModel(setup).parameter_block_sizes(), std::vector<int>{1});
}

TEST(RegionCalibrationTest, RejectsInvalidRegionParametersWithMessages) {
  auto message = [](const CalibrationSetup& s) -> std::string {
    try {
      CalibrationModel model(s);
    } catch (const InvalidInputError& e) {
      return e.what();
    }
    return "";
  };
  CalibrationSetup s = ThreePartSetup(Method::kNewtonCholesky, false, JacobianMode::kForward);
  s.fitted_regions = {{0, MaterialParameter::kDensity}, {2, MaterialParameter::kDensity}};
  EXPECT_EQ(message(s), "fitted_regions[1]: region 2 is out of range [0, 2)");
  s.fitted_regions = {{-1, MaterialParameter::kDensity}};
  EXPECT_EQ(message(s), "fitted_regions[0]: region -1 is out of range [0, 2)");
  s.fitted_regions = {{1, MaterialParameter::kYoungsModulus},
                      {0, MaterialParameter::kYoungsModulus},
                      {1, MaterialParameter::kYoungsModulus}};
  EXPECT_EQ(message(s), "fitted_regions lists youngs_modulus of region 1 twice");
  s.fitted.clear();
  s.fitted_regions.clear();
  EXPECT_EQ(message(s), "nothing to fit: `fitted` and `fitted_regions` are empty and there are no input_parameters");
}

// A cantilever whose clamped half is stiff (base material, E = 2e5 Pa) and
// whose free half is 5x softer (region 0): both moduli and Poisson's ratios
// recovered from noise-free markers, starting 50% / 0.1 off.
TEST(RegionCalibrationTest, RecoversAStiffAndASoftHalfFromNoiseFreeMarkers) {
  Scene truth = testing::SmallBeamScene();
  truth.material = MaterialParameters{2e5, 0.4, 1e3};
  MaterialRegion soft;
  soft.elements = testing::ElementsWithCentroidX(truth.mesh, 0.08, 1.0);
  soft.material = MaterialParameters{4e4, 0.3, 1e3};
  truth.material_regions = {soft};
  CalibrationSetup setup = testing::SyntheticSetupFromScene(truth, Method::kNewtonCholesky, 8);
  setup.scene.material = MaterialParameters{1e5, 0.3, 1e3};
  setup.scene.material_regions[0].material = MaterialParameters{1e5, 0.4, 1e3};
  setup.fitted = {MaterialParameter::kYoungsModulus, MaterialParameter::kPoissonsRatio};
  setup.fitted_regions = {{0, MaterialParameter::kYoungsModulus}, {0, MaterialParameter::kPoissonsRatio}};
  ceres::Solver::Summary summary;
  const std::vector<double> material = testing::FitMaterialBlock(setup, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_NEAR(material[0] / 2e5, 1.0, 1e-5) << summary.FullReport();
  EXPECT_NEAR(material[1] / 0.4, 1.0, 1e-5);
  EXPECT_NEAR(material[2] / 4e4, 1.0, 1e-5);
  EXPECT_NEAR(material[3] / 0.3, 1.0, 1e-5);
  EXPECT_LT(summary.final_cost, 1e-10);
}

}  // namespace
}  // namespace diffpd::solvers
