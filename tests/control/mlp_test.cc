// The multilayer perceptron: its vector-Jacobian products against central
// differences (input and weights, tanh and identity layers), the orthogonal
// initialisation (orthonormal rows or columns times the gain, zero biases,
// the same for a seed and different across seeds) and its input checks.
#include "diffpd/mlp.h"

#include <gtest/gtest.h>

#include <random>

#include "diffpd/error.h"
#include "test_scenes.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

using testing::RandomVector;

Mlp RandomNetwork(std::vector<int> widths, MlpNonlinearity output, std::uint64_t seed) {
  Mlp mlp(std::move(widths), MlpNonlinearity::kTanh, output);
  mlp.InitializeOrthogonal(seed, 5.0 / 3.0);
  std::mt19937_64 rng(seed);
  // Non-zero biases too, so that their gradient is exercised.
  VectorXd theta = mlp.parameters() + RandomVector(mlp.num_parameters(), &rng, 0.1);
  mlp.SetParameters(theta);
  return mlp;
}

struct Case {
  std::vector<int> widths;
  MlpNonlinearity output;
};

class MlpVjpTest : public ::testing::TestWithParam<Case> {};

TEST_P(MlpVjpTest, InputAndWeightGradientsMatchCentralDifferences) {
  const Case c = GetParam();
  const Mlp mlp = RandomNetwork(c.widths, c.output, 11);
  std::mt19937_64 rng(3);
  const VectorXd input = RandomVector(mlp.num_inputs(), &rng, 0.5);
  const VectorXd g_out = RandomVector(mlp.num_outputs(), &rng, 1.0);
  MlpTape tape;
  const VectorXd y = mlp.Forward(input, &tape);
  EXPECT_EQ(y, mlp.Evaluate(input));
  VectorXd g_in, g_theta = VectorXd::Zero(mlp.num_parameters());
  mlp.Backward(tape, g_out, &g_in, &g_theta);

  const auto of_input = [&](const VectorXd& z) { return g_out.dot(mlp.Evaluate(z)); };
  EXPECT_TRUE(testing::Passes(testing::CheckGradient(of_input, input, g_in)));
  const auto of_theta = [&](const VectorXd& theta) {
    Mlp m = mlp;
    m.SetParameters(theta);
    return g_out.dot(m.Evaluate(input));
  };
  // Directions in weight space (the full gradient would take 2 evaluations per weight).
  for (int d = 0; d < 3; ++d) {
    const VectorXd dir = RandomVector(mlp.num_parameters(), &rng, 1.0);
    EXPECT_TRUE(
        testing::Passes(testing::CheckDirectionalDerivative(of_theta, mlp.parameters(), dir, g_theta.dot(dir))));
  }
  // Backward adds to g_parameters and may skip the input gradient.
  VectorXd twice = g_theta;
  mlp.Backward(tape, g_out, nullptr, &twice);
  EXPECT_TRUE(twice.isApprox(2 * g_theta, 1e-15));
}

INSTANTIATE_TEST_SUITE_P(Widths, MlpVjpTest,
                         ::testing::Values(Case{{5, 7, 6, 3}, MlpNonlinearity::kTanh},
                                           Case{{4, 2}, MlpNonlinearity::kIdentity},
                                           Case{{3, 9, 1}, MlpNonlinearity::kIdentity}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string name;
                           for (int w : info.param.widths) name += std::to_string(w) + "_";
                           return name + (info.param.output == MlpNonlinearity::kTanh ? "tanh" : "identity");
                         });

TEST(MlpTest, OrthogonalInitialisationHasOrthonormalRowsOrColumnsTimesTheGainAndZeroBiases) {
  Mlp mlp({243, 64, 64, 4}, MlpNonlinearity::kTanh, MlpNonlinearity::kTanh);
  const double gain = 5.0 / 3.0;
  mlp.InitializeOrthogonal(42, gain);
  ASSERT_EQ(mlp.num_parameters(), 64 * 244 + 64 * 65 + 4 * 65);
  int offset = 0;
  for (int l = 0; l < mlp.num_layers(); ++l) {
    const int rows = mlp.widths()[l + 1], cols = mlp.widths()[l];
    const Eigen::Map<const MatrixXd> w(mlp.parameters().data() + offset, rows, cols);
    const MatrixXd gram = rows <= cols ? MatrixXd(w * w.transpose()) : MatrixXd(w.transpose() * w);
    EXPECT_LT((gram - gain * gain * MatrixXd::Identity(gram.rows(), gram.cols())).norm(), 1e-12) << "layer " << l;
    EXPECT_EQ(mlp.parameters().segment(offset + rows * cols, rows).norm(), 0.0) << "layer " << l;
    offset += rows * (cols + 1);
  }
  Mlp again({243, 64, 64, 4}, MlpNonlinearity::kTanh, MlpNonlinearity::kTanh);
  again.InitializeOrthogonal(42, gain);
  EXPECT_EQ(again.parameters(), mlp.parameters());
  again.InitializeOrthogonal(43, gain);
  EXPECT_GT((again.parameters() - mlp.parameters()).norm(), 1.0);
}

TEST(MlpTest, RefusesInvalidWidthsParametersAndInputs) {
  EXPECT_THROW_MESSAGE(Mlp({3}), InvalidInputError, "Mlp: 1 widths given, need at least 2 (inputs and outputs)");
  EXPECT_THROW_MESSAGE(Mlp({3, 4, 0}), InvalidInputError, "Mlp: widths[2] = 0 is invalid: must be >= 1");
  Mlp mlp({4, 3});
  EXPECT_THROW_MESSAGE(mlp.SetParameters(VectorXd::Zero(3)), InvalidInputError,
                       "Mlp: parameters have 3 entries, expected 15");
  VectorXd bad = VectorXd::Zero(15);
  bad(4) = NAN;
  EXPECT_THROW_MESSAGE(mlp.SetParameters(bad), InvalidInputError, "Mlp: parameters have a non-finite entry");
  EXPECT_THROW_MESSAGE(mlp.Evaluate(VectorXd::Zero(3)), InvalidInputError, "Mlp: input has 3 entries, expected 4");
  EXPECT_THROW_MESSAGE(mlp.InitializeOrthogonal(1, INFINITY), InvalidInputError,
                       "Mlp: gain = inf is invalid: must be finite");
}

}  // namespace
}  // namespace diffpd
