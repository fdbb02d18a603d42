// Bad solver options, scenes and inputs are rejected with messages naming
// the input and its valid range.
#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

// The message of the InvalidInputError f() throws.
template <class F>
std::string MessageOf(F&& f) {
  return testing::MessageOf<InvalidInputError>(std::forward<F>(f));
}

TEST(SolverOptionsTest, InvalidFieldsAreRejectedWithTheFieldAndRange) {
  SolverOptions o;
  o.time_step = 0;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }), "solver options: time_step = 0 is invalid: must be finite and > 0 (s)");
  o = SolverOptions();
  o.time_step = NAN;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }), "solver options: time_step = nan is invalid: must be finite and > 0 (s)");
  o = SolverOptions();
  o.rel_tolerance = 1.5;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }), "solver options: rel_tolerance = 1.5 is invalid: must be in [0, 1)");
  o = SolverOptions();
  o.max_iterations = 0;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }), "solver options: max_iterations = 0 is invalid: must be >= 1");
  o = SolverOptions();
  o.num_threads = -2;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }),
            "solver options: num_threads = -2 is invalid: must be >= 0 (0: OpenMP default)");
  o = SolverOptions();
  o.lbfgs_weight_scale = 0;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }), "solver options: lbfgs_weight_scale = 0 is invalid: must be in (0, 1]");
  o.lbfgs_weight_scale = 1.5;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }), "solver options: lbfgs_weight_scale = 1.5 is invalid: must be in (0, 1]");
  o = SolverOptions();
  o.backward_rel_tolerance = -1e-6;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }),
            "solver options: backward_rel_tolerance = -1e-06 is invalid: must be in [0, 1) (0: derived from the "
            "forward's accuracy)");
  o = SolverOptions();
  o.backward_tolerance_factor = 0;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }),
            "solver options: backward_tolerance_factor = 0 is invalid: must be in (0, 1]");
  o = SolverOptions();
  o.adjoint_guess_solutions = -1;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }), "solver options: adjoint_guess_solutions = -1 is invalid: must be >= 0");
  o = SolverOptions();
  o.adjoint_solver = static_cast<AdjointSolver>(7);
  EXPECT_EQ(MessageOf([&] { o.Validate(); }),
            "solver options: adjoint_solver = 7 is invalid: must be auto, iterative or direct (AdjointSolver)");
  o = SolverOptions();
  o.abs_tolerance = 0;
  o.rel_tolerance = 0;
  EXPECT_EQ(MessageOf([&] { o.Validate(); }),
            "solver options: abs_tolerance and rel_tolerance are both 0; at least one must be > 0");
}

TEST(SolverOptionsTest, MethodNamesRoundTripAndUnknownNamesAreListed) {
  for (const Method m : {Method::kSemiImplicit, Method::kNewtonCholesky, Method::kNewtonPcg, Method::kPd,
                         Method::kPdLbfgs, Method::kNewtonLdlt})
    EXPECT_EQ(ParseMethod(ToString(m)), m);
  EXPECT_EQ(ToString(Method::kNewtonLdlt), std::string("newton-ldlt"));
  EXPECT_EQ(MessageOf([] { ParseMethod("newton"); }),
            "unknown method 'newton': valid methods are semi-implicit, newton-cholesky, newton-pcg, pd, pd-lbfgs, "
            "newton-ldlt");
  for (const AdjointSolver a : {AdjointSolver::kAuto, AdjointSolver::kIterative, AdjointSolver::kDirect})
    EXPECT_EQ(ParseAdjointSolver(ToString(a)), a);
  EXPECT_EQ(MessageOf([] { ParseAdjointSolver("cg"); }),
            "unknown adjoint solver 'cg': valid adjoint solvers are auto, iterative, direct");
}

TEST(SolverOptionsTest, BadScenesAndInputsAreRejected) {
  Scene scene = testing::SmallBeamScene();
  scene.energies.clear();
  EXPECT_EQ(MessageOf([&] { Simulator(scene, SolverOptions()); }),
            "scene: no elastic energy declared (energies is empty)");
  scene = testing::SmallBeamScene();
  scene.dirichlet.dofs.push_back(1000000);
  scene.dirichlet.values.conservativeResize(scene.dirichlet.values.size() + 1);
  scene.dirichlet.values(scene.dirichlet.values.size() - 1) = 0;
  EXPECT_EQ(MessageOf([&] { Simulator(scene, SolverOptions()); }),
            "scene: Dirichlet DoF 1000000 is out of range [0, 135)");
  scene = testing::SmallBeamScene();
  scene.material.poissons_ratio = 0.5;
  EXPECT_EQ(MessageOf([&] { Simulator(scene, SolverOptions()); }),
            "poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");

  Simulator sim(testing::SmallBeamScene(), SolverOptions());
  State s = sim.RestState();
  s.v.resize(3);
  EXPECT_EQ(MessageOf([&] { sim.Step(s, StepInput()); }), "state.v has 3 entries, expected 135 (3 x number of nodes)");
  s = sim.RestState();
  s.x(4) = NAN;
  EXPECT_EQ(MessageOf([&] { sim.Step(s, StepInput()); }), "state.x has a non-finite entry");
  StepInput in;
  in.external_force = VectorXd::Zero(sim.num_dofs());
  in.external_force(0) = INFINITY;
  EXPECT_EQ(MessageOf([&] { sim.Step(sim.RestState(), in); }), "external_force has a non-finite entry");
}

TEST(SolverOptionsTest, AnExplicitStepTooLargeIsReportedAsNonFinite) {
  Scene scene = testing::SmallBeamScene();
  scene.material.youngs_modulus = 1e9;
  SolverOptions o;
  o.method = Method::kSemiImplicit;
  o.time_step = 0.01;
  Simulator sim(scene, o);
  State s = sim.RestState();
  s.x(s.x.size() - 1) += 0.01;
  try {
    for (int k = 0; k < 2000; ++k) s = sim.Step(s, StepInput());
    FAIL() << "expected SolverError";
  } catch (const SolverError& e) {
    EXPECT_EQ(e.status(), SolverStatus::kNonFinite);
  }
}

}  // namespace
}  // namespace diffpd
