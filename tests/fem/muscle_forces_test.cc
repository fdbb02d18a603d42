// Muscle fibre energy (k/2) vol (|F m| - a)^2: conformance (zero at rest,
// rotation invariance, gradient, Hessian and activation derivative vs finite
// differences, PD matrix = Hessian at a = 0, SPD projection) and whole-rollout
// activation gradients for PD and Newton.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "fem/fem_model.h"
#include "fem/muscle_forces.h"
#include "tools/gradcheck.h"
#include "test_scenes.h"
#include "util/expect_message.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

VectorXd Random(int n, std::mt19937_64* rng, double scale = 1.0) {
  std::normal_distribution<double> normal(0.0, scale);
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

struct MuscleFixture {
  explicit MuscleFixture(bool tets)
      : mesh(tets ? testing::BoxTetMesh(2, 1, 1, 0.1, 0.05, 0.05) : testing::BoxHexMesh(2, 1, 1, 0.1, 0.05, 0.05)),
        fem(mesh) {
    Muscle a;
    a.elements = {0, 1};
    a.fibers = {Vec3(1, 0, 0), Vec3(1, 1, 0)};
    a.stiffness = 2e5;
    Muscle b;
    b.elements = {1};
    b.fibers = {Vec3(0, 0, 3)};
    b.stiffness = 5e4;
    muscles = {a, b};
    forces = std::make_unique<internal::MuscleForces>(fem, muscles);
  }
  VectorXd Rest() const { return Eigen::Map<const VectorXd>(mesh.vertices.data(), mesh.num_dofs()); }
  Mesh mesh;
  internal::FemModel fem;
  std::vector<Muscle> muscles;
  std::unique_ptr<internal::MuscleForces> forces;
};

class MuscleForcesTest : public ::testing::TestWithParam<bool> {};

TEST_P(MuscleForcesTest, RestActivationHasZeroEnergyAndForceAtRest) {
  MuscleFixture f(GetParam());
  VectorXd grad = VectorXd::Zero(f.mesh.num_dofs());
  EXPECT_NEAR(f.forces->AddEnergyAndGradient(f.Rest(), VectorXd(), &grad), 0.0, 1e-20);
  EXPECT_LT(grad.norm(), 1e-10);
  // A contracted activation pulls: positive energy, non-zero force.
  EXPECT_GT(f.forces->AddEnergyAndGradient(f.Rest(), Eigen::Vector2d(0.8, 1.0), nullptr), 0.0);
}

TEST_P(MuscleForcesTest, EnergyIsInvariantUnderRigidMotion) {
  MuscleFixture f(GetParam());
  std::mt19937_64 rng(3);
  const VectorXd x = f.Rest() + Random(f.mesh.num_dofs(), &rng, 0.005);
  const Eigen::Vector2d a(0.85, 1.1);
  const Mat3 r = Eigen::AngleAxisd(0.7, Vec3(1, 2, -1).normalized()).toRotationMatrix();
  VectorXd y(x.size());
  for (int i = 0; i < f.mesh.num_vertices(); ++i) y.segment<3>(3 * i) = r * x.segment<3>(3 * i) + Vec3(0.3, -1, 2);
  EXPECT_NEAR(f.forces->AddEnergyAndGradient(x, a, nullptr), f.forces->AddEnergyAndGradient(y, a, nullptr),
              1e-12 * f.forces->AddEnergyAndGradient(x, a, nullptr));
}

TEST_P(MuscleForcesTest, GradientHessianAndActivationDerivativeMatchFiniteDifferences) {
  MuscleFixture f(GetParam());
  std::mt19937_64 rng(5);
  const int n = f.mesh.num_dofs();
  for (int trial = 0; trial < 3; ++trial) {
    const VectorXd x = f.Rest() + Random(n, &rng, 0.01);
    const Eigen::Vector2d a(0.8 + 0.1 * trial, 1.05);
    const VectorXd d = Random(n, &rng);
    // E(x), grad E(x) at activation a, and -d . grad E(x) at activations b.
    const auto gradient_at = [&](const VectorXd& y, const VectorXd& b) {
      VectorXd g = VectorXd::Zero(n);
      f.forces->AddEnergyAndGradient(y, b, &g);
      return g;
    };
    const auto energy = [&](const VectorXd& y) { return f.forces->AddEnergyAndGradient(y, a, nullptr); };
    const auto gradient = [&](const VectorXd& y) { return gradient_at(y, a); };
    const auto minus_d_dot_gradient = [&](const VectorXd& b) { return -d.dot(gradient_at(x, b)); };
    VectorXd hd = VectorXd::Zero(n);
    f.forces->AddHessianProduct(x, a, d, &hd);
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(energy, x, d, gradient(x).dot(d))));
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(gradient, x, d, hd)));
    // dL/da_j = -z . d(grad)/da_j with z = d.
    const VectorXd ga = f.forces->ActivationGradient(x, a, d);
    for (int j = 0; j < 2; ++j) {
      EXPECT_TRUE(testing::Passes(
          testing::CheckDirectionalDerivative(minus_d_dot_gradient, a, Eigen::Vector2d::Unit(j), ga(j))))
          << "activation " << j;
    }
  }
}

TEST_P(MuscleForcesTest, ElementHessiansAssembleToTheHessianProductAndProjectToPsd) {
  MuscleFixture f(GetParam());
  std::mt19937_64 rng(7);
  const int n = f.mesh.num_dofs();
  const int k = f.fem.nodes_per_element(), nb = 3 * k;
  const VectorXd x = f.Rest() + Random(n, &rng, 0.01);
  const Eigen::Vector2d a(1.3, 1.4);  // stretched beyond the fibre: indefinite exact Hessian
  for (const bool project : {false, true}) {
    std::vector<double> blocks(static_cast<size_t>(f.mesh.num_elements()) * nb * nb, 0.0);
    f.forces->AddElementHessians(x, a, project, &blocks);
    MatrixXd h = MatrixXd::Zero(n, n);
    for (int e = 0; e < f.mesh.num_elements(); ++e) {
      const Eigen::Map<const MatrixXd> ke(blocks.data() + static_cast<size_t>(e) * nb * nb, nb, nb);
      for (int p = 0; p < nb; ++p)
        for (int q = 0; q < nb; ++q)
          h(3 * f.mesh.elements(p / 3, e) + p % 3, 3 * f.mesh.elements(q / 3, e) + q % 3) += ke(p, q);
    }
    const double min_eig = Eigen::SelfAdjointEigenSolver<MatrixXd>(h).eigenvalues().minCoeff();
    if (project) {
      EXPECT_GT(min_eig, -1e-9 * h.norm());
    } else {
      EXPECT_LT(min_eig, -1e-6 * h.norm());  // the exact Hessian is indefinite here
      const VectorXd z = Random(n, &rng);
      VectorXd hz = VectorXd::Zero(n);
      f.forces->AddHessianProduct(x, a, z, &hz);
      EXPECT_LT((h * z - hz).norm(), 1e-10 * hz.norm());
    }
  }
}

// At a = 0 the energy is (w/2)|G x|^2, whose Hessian is exactly the PD term w G^T G (x) I3.
TEST_P(MuscleForcesTest, PdMatrixTermEqualsTheHessianAtZeroActivation) {
  MuscleFixture f(GetParam());
  std::vector<Eigen::Triplet<double>> triplets;
  f.forces->AddPdTriplets(&triplets);
  const int nn = f.mesh.num_vertices();
  SparseMatrix a_s(nn, nn);
  a_s.setFromTriplets(triplets.begin(), triplets.end());
  std::mt19937_64 rng(9);
  const VectorXd x = f.Rest() + Random(3 * nn, &rng, 0.01);
  const VectorXd z = Random(3 * nn, &rng);
  VectorXd hz = VectorXd::Zero(3 * nn);
  f.forces->AddHessianProduct(x, Eigen::Vector2d::Zero(), z, &hz);
  for (int d = 0; d < 3; ++d) {
    VectorXd zd(nn), hd(nn);
    for (int i = 0; i < nn; ++i) {
      zd(i) = z(3 * i + d);
      hd(i) = hz(3 * i + d);
    }
    EXPECT_LT((a_s * zd - hd).norm(), 1e-10 * hd.norm());
  }
}

INSTANTIATE_TEST_SUITE_P(HexAndTet, MuscleForcesTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) { return info.param ? "tet" : "hex"; });

Scene MuscleBeam() {
  Scene scene = testing::SmallBeamScene();
  Muscle top, bottom;
  for (int e = 0; e < scene.mesh.num_elements(); ++e) {
    Vec3 c = Vec3::Zero();
    for (int a = 0; a < 8; ++a) c += scene.mesh.vertices.col(scene.mesh.elements(a, e)) / 8.0;
    (c(2) > 0.02 ? top : bottom).elements.push_back(e);
  }
  top.fibers = {Vec3(1, 0, 0)};
  bottom.fibers = {Vec3(1, 0, 0.2)};
  top.stiffness = 1e5;
  bottom.stiffness = 2e5;
  scene.muscles = {top, bottom};
  return scene;
}

TEST(MuscleRolloutTest, ContractingTheTopMuscleBendsTheBeamUpward) {
  const Scene scene = MuscleBeam();
  SolverOptions options;
  options.method = Method::kPd;
  Simulator sim(scene, options);
  StepInput contract;
  contract.activation = Eigen::Vector2d(0.9, 1.0);
  const VectorXd rest_tip = sim.SolveQuasiStatic(sim.RestState().x, StepInput());
  const VectorXd bent = sim.SolveQuasiStatic(sim.RestState().x, contract);
  double dz = 0;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) > 0.159) dz += bent(3 * i + 2) - rest_tip(3 * i + 2);
  EXPECT_GT(dz, 1e-3);  // the tip rises when the top fibres shorten
}

class MuscleGradientTest : public ::testing::TestWithParam<Method> {};

TEST_P(MuscleGradientTest, RolloutGradientsIncludingActivationsMatchFiniteDifferences) {
  const Scene scene = MuscleBeam();
  SolverOptions options;
  options.method = GetParam();
  // PD's linear convergence is fast when M/h^2 dominates A: a short step keeps the test quick.
  options.time_step = GetParam() == Method::kSemiImplicit ? 2e-4 : 0.004;
  options.rel_tolerance = 1e-12;
  options.abs_tolerance = 1e-11;
  options.backward_rel_tolerance = 1e-13;
  options.max_iterations = 20000;
  options.num_threads = 1;
  Simulator sim(scene, options);
  State initial = sim.RestState();
  for (int i = 0; i < initial.x.size() / 3; ++i) initial.v(3 * i + 2) = 0.3 * initial.x(3 * i);
  const int steps = GetParam() == Method::kSemiImplicit ? 10 : 3;
  const problems::GradCheckResult result = problems::CheckRolloutGradient(scene, options, initial, steps);
  bool found = false;
  for (const auto& entry : result.inputs) {
    EXPECT_LT(entry.max_rel_error, 1e-5) << ToString(GetParam()) << " input " << entry.input;
    found = found || entry.input == "activation";
  }
  EXPECT_TRUE(found);
}

INSTANTIATE_TEST_SUITE_P(Methods, MuscleGradientTest,
                         ::testing::Values(Method::kPd, Method::kNewtonCholesky, Method::kSemiImplicit),
                         [](const ::testing::TestParamInfo<Method>& info) {
                           std::string name = ToString(info.param);
                           for (char& ch : name)
                             if (ch == '-') ch = '_';
                           return name;
                         });

TEST(MuscleRolloutTest, BadActivationIsRejectedWithAClearMessage) {
  Simulator sim(MuscleBeam(), SolverOptions());
  StepInput wrong_size;
  wrong_size.activation = Eigen::Vector3d(1, 1, 1);
  ASSERT_THROW_MESSAGE(sim.Step(sim.RestState(), wrong_size), InvalidInputError,
                       "activation has 3 entries, expected 2 (one per muscle)");
  StepInput nan;
  nan.activation = Eigen::Vector2d(1, std::nan(""));
  try {
    sim.Step(sim.RestState(), nan);
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "activation[1] = nan is invalid: must be finite");
  }
}

TEST(MuscleRolloutTest, ANegativeActivationBendsTheBeamFurtherThanZero) {
  // (|F m| - a)^2 with a < 0 pulls the fibre toward zero length harder than a = 0.
  const Scene scene = MuscleBeam();
  Simulator sim(scene, SolverOptions());
  StepInput zero, negative;
  zero.activation = Eigen::Vector2d(0.0, 1.0);
  negative.activation = Eigen::Vector2d(-0.3, 1.0);
  const VectorXd at_zero = sim.SolveQuasiStatic(sim.RestState().x, zero);
  const VectorXd at_negative = sim.SolveQuasiStatic(sim.RestState().x, negative);
  double dz = 0;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) > 0.159) dz += at_negative(3 * i + 2) - at_zero(3 * i + 2);
  EXPECT_GT(dz, 1e-4);
}

}  // namespace
}  // namespace diffpd
