// CalibrationModel (calibration_model.h): forward- and reverse-mode
// Jacobians agree with each other and with central finite differences of
// the residuals (material and input blocks), and the validation of setups.
// Recovery of known parameters: ceres_calibration_recovery_test.cc.
#include <gtest/gtest.h>

#include "ceres_calibration_fixture.h"
#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

// All residual Jacobians of a setup at `blocks` by the given mode.
std::vector<MatrixXd> Jacobians(CalibrationSetup setup, JacobianMode mode, const std::vector<double*>& blocks,
                                VectorXd* residuals = nullptr) {
  setup.jacobian = mode;
  CalibrationModel model(setup);
  EXPECT_TRUE(model.Evaluate(blocks.data(), true)) << model.statistics().last_error;
  if (residuals) *residuals = model.residuals();
  std::vector<MatrixXd> out;
  for (size_t b = 0; b < blocks.size(); ++b) out.push_back(model.jacobian(static_cast<int>(b)));
  return out;
}

struct ModeCase {
  Method method;
  bool tets;
};

class CalibrationJacobianTest : public ::testing::TestWithParam<ModeCase> {};

TEST_P(CalibrationJacobianTest, ForwardAndReverseAgreeAndMatchFiniteDifferences) {
  const ModeCase c = GetParam();
  CalibrationSetup setup = testing::SyntheticSetup(c.method, c.tets, testing::TrueMaterial(), 6);
  setup.fitted = {MaterialParameter::kYoungsModulus, MaterialParameter::kPoissonsRatio, MaterialParameter::kDensity};
  // An input block acting on the initial position (a shear), the initial
  // velocity and a force held over steps 1..3.
  const int n = setup.scene.mesh.num_dofs();
  MatrixXd xb = MatrixXd::Zero(n, 2), vb = MatrixXd::Zero(n, 2), fb = MatrixXd::Zero(n, 2);
  for (int i = 0; i < n / 3; ++i) {
    const double x = setup.scene.mesh.vertices(0, i);
    xb(3 * i + 2, 0) = 0.1 * x;
    vb(3 * i + 1, 1) = x;
    fb(3 * i + 2, 1) = -0.01;
  }
  setup.input_parameters = std::make_shared<LinearInputParameters>(xb, vb, fb, 1, 4);
  std::vector<double> material = {1.7e5, 0.37, 1.1e3};
  std::vector<double> inputs = {0.02, -0.3};
  const std::vector<double*> blocks = {material.data(), inputs.data()};
  VectorXd r0;
  const std::vector<MatrixXd> forward = Jacobians(setup, JacobianMode::kForward, blocks, &r0);
  const std::vector<MatrixXd> reverse = Jacobians(setup, JacobianMode::kReverse, blocks);
  for (int b = 0; b < 2; ++b) {
    ASSERT_EQ(forward[b].rows(), r0.size());
    EXPECT_LT((forward[b] - reverse[b]).norm(), 1e-9 * forward[b].norm()) << "block " << b;
  }
  // Central differences, one parameter at a time, relative step 1e-4; PD's
  // linearly converging forward solves make its differences noisier.
  const double fd_tolerance = c.method == Method::kPd ? 1e-5 : 1e-6;
  CalibrationModel model(setup);
  for (int b = 0; b < 2; ++b) {
    std::vector<double>& values = b == 0 ? material : inputs;
    for (size_t i = 0; i < values.size(); ++i) {
      const double saved = values[i];
      const double eps = 1e-4 * std::max(std::abs(saved), 1e-2);
      values[i] = saved + eps;
      ASSERT_TRUE(model.Evaluate(blocks.data(), false));
      const VectorXd plus = model.residuals();
      values[i] = saved - eps;
      ASSERT_TRUE(model.Evaluate(blocks.data(), false));
      const VectorXd fd = (plus - model.residuals()) / (2 * eps);
      values[i] = saved;
      EXPECT_LT((forward[b].col(i) - fd).norm(), fd_tolerance * fd.norm()) << "block " << b << " parameter " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, CalibrationJacobianTest,
                         ::testing::Values(ModeCase{Method::kNewtonCholesky, false}, ModeCase{Method::kPd, true}),
                         [](const ::testing::TestParamInfo<ModeCase>& info) {
                           return std::string(info.param.method == Method::kPd ? "pd" : "newton_cholesky") +
                                  (info.param.tets ? "_tet" : "_hex");
                         });

TEST(CalibrationModelTest, RejectsInvalidSetupsWithMessages) {
  auto message = [](CalibrationSetup setup) {
    try {
      CalibrationModel model(std::move(setup));
    } catch (const InvalidInputError& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  const CalibrationSetup good = testing::SyntheticSetup(Method::kNewtonCholesky, true, testing::TrueMaterial(), 4);
  EXPECT_EQ(message(good), "no exception");
  CalibrationSetup s = good;
  s.fitted = {};
  EXPECT_EQ(message(s), "nothing to fit: `fitted` and `fitted_regions` are empty and there are no input_parameters");
  s.fitted = {MaterialParameter::kDensity, MaterialParameter::kDensity};
  EXPECT_EQ(message(s), "fitted lists density twice");
  s = good;
  s.num_steps = 2;  // frames at 0.015 and 0.03 s, 4 markers each
  EXPECT_EQ(message(s), "sample 4: time 0.03 s is after the end of the simulation (2 steps of 0.01 s = 0.02 s)");
  s = good;
  s.inputs.resize(2);
  EXPECT_EQ(message(s), "inputs has 2 steps, expected 4");
  s = good;
  s.initial->v.resize(5);
  EXPECT_EQ(message(s), "initial state has " + std::to_string(good.scene.mesh.num_dofs()) +
                            " positions and 5 velocities, expected " + std::to_string(good.scene.mesh.num_dofs()) +
                            " each");
  s = good;
  s.motion.markers[0].vertex = 10000;
  EXPECT_EQ(message(s).rfind("marker 0: vertex 10000 is out of range (the mesh has ", 0), 0u) << message(s);
  EXPECT_THROW(LinearInputParameters(MatrixXd(), MatrixXd()), InvalidInputError);
  try {
    LinearInputParameters(MatrixXd::Zero(6, 2), MatrixXd::Zero(6, 3));
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "velocity_basis has 3 columns, but another basis has 2");
  }
  try {
    LinearInputParameters(MatrixXd(), MatrixXd(), MatrixXd::Zero(6, 1), 3, 2);
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "force_begin = 3, force_end = 2 is invalid: need 0 <= begin <= end");
  }
}

}  // namespace
}  // namespace diffpd::solvers
