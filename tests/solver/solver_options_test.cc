// Bad solver options, scenes and inputs are rejected with messages naming
// the input and its valid range.
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <functional>
#include <string>

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

// One spoilt field of the default options and the exact message.
struct BadOptions {
  std::function<void(SolverOptions*)> spoil;
  std::string message;
};

TEST(SolverOptionsTest, InvalidFieldsAreRejectedWithTheFieldAndRange) {
  const std::string threads = std::to_string(MaxSolverThreads());
  const std::string processors = std::to_string(omp_get_num_procs());
  const BadOptions cases[] = {
      {[](SolverOptions* o) { o->time_step = 0; },
       "solver options: time_step = 0 is invalid: must be finite and > 0 (s)"},
      {[](SolverOptions* o) { o->time_step = NAN; },
       "solver options: time_step = nan is invalid: must be finite and > 0 (s)"},
      {[](SolverOptions* o) { o->rel_tolerance = 1.5; },
       "solver options: rel_tolerance = 1.5 is invalid: must be in [0, 1)"},
      {[](SolverOptions* o) { o->max_iterations = 0; }, "solver options: max_iterations = 0 is invalid: must be >= 1"},
      {[](SolverOptions* o) { o->num_threads = -2; }, "solver options: num_threads = -2 is invalid: must be in [0, " +
                                                          threads + "] (0: OpenMP default; at most 4 x the " +
                                                          processors + " processors)"},
      {[](SolverOptions* o) { o->num_threads = 99999; },
       "solver options: num_threads = 99999 is invalid: must be in [0, " + threads +
           "] (0: OpenMP default; at most 4 x the " + processors + " processors)"},
      {[](SolverOptions* o) { o->lbfgs_weight_scale = 0; },
       "solver options: lbfgs_weight_scale = 0 is invalid: must be in (0, 1]"},
      {[](SolverOptions* o) { o->lbfgs_weight_scale = 1.5; },
       "solver options: lbfgs_weight_scale = 1.5 is invalid: must be in (0, 1]"},
      {[](SolverOptions* o) { o->abs_tolerance = o->rel_tolerance = 0; },
       "solver options: abs_tolerance and rel_tolerance are both 0; at least one must be > 0"},
      {[](SolverOptions* o) { o->max_extent_ratio = 1; },
       "solver options: max_extent_ratio = 1 is invalid: must be > 1 (infinity: no bound)"},
      {[](SolverOptions* o) { o->max_extent_ratio = NAN; },
       "solver options: max_extent_ratio = nan is invalid: must be > 1 (infinity: no bound)"},
      // Integers cast to the enums.
      {[](SolverOptions* o) { o->method = static_cast<Method>(7); },
       "solver options: method = 7 is invalid: must be a Method: semi-implicit (0), newton-cholesky (1), newton-pcg "
       "(2), pd (3) or pd-lbfgs (4)"},
      {[](SolverOptions* o) { o->method = static_cast<Method>(-1); },
       "solver options: method = -1 is invalid: must be a Method: semi-implicit (0), newton-cholesky (1), newton-pcg "
       "(2), pd (3) or pd-lbfgs (4)"},
      {[](SolverOptions* o) { o->pcg_preconditioner = static_cast<PcgPreconditioner>(2); },
       "solver options: pcg_preconditioner = 2 is invalid: must be kJacobi (0) or kIncompleteCholesky (1)"},
      {[](SolverOptions* o) { o->pd_backward = static_cast<PdBackwardMethod>(3); },
       "solver options: pd_backward = 3 is invalid: must be kFixedPoint (0), kLbfgs (1) or kConjugateGradient (2)"},
  };
  for (const BadOptions& c : cases) {
    SolverOptions o;
    c.spoil(&o);
    EXPECT_EQ(MessageOf([&] { o.Validate(); }), c.message);
    // The simulator validates the same way, at construction and in SetOptions.
    EXPECT_EQ(MessageOf([&] { Simulator(testing::SmallBeamScene(), o); }), c.message);
  }
  SolverOptions most;
  most.num_threads = MaxSolverThreads();
  EXPECT_NO_THROW(most.Validate());
}

TEST(SolverOptionsTest, MethodNamesRoundTripAndUnknownNamesAreListed) {
  for (const Method m :
       {Method::kSemiImplicit, Method::kNewtonCholesky, Method::kNewtonPcg, Method::kPd, Method::kPdLbfgs})
    EXPECT_EQ(ParseMethod(ToString(m)), m);
  EXPECT_EQ(MessageOf([] { ParseMethod("newton"); }),
            "unknown method 'newton': valid methods are semi-implicit, newton-cholesky, newton-pcg, pd, pd-lbfgs");
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

TEST(SolverOptionsTest, AnExplicitStepTooLargeIsReportedAsDiverged) {
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
    EXPECT_EQ(e.status(), SolverStatus::kDiverged) << e.what();
  }
}

}  // namespace
}  // namespace diffpd
