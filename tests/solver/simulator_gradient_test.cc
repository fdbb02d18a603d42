// Rollout gradients of every method and input kind vs central finite
// differences (every input kind passes the check with a margin of at least
// 10 at tolerance 1e-4), on small hex and tet meshes.
#include <gtest/gtest.h>

#include "diffpd/simulator.h"
#include "tools/gradcheck.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

// One random direction per input kind (the check's default is two).
problems::GradCheckOptions OneDirection() {
  problems::GradCheckOptions check;
  check.directions = 1;
  return check;
}

struct Case {
  Method method;
  bool tets;
};

class SimulatorGradientTest : public ::testing::TestWithParam<Case> {};

TEST_P(SimulatorGradientTest, MatchesCentralFiniteDifferencesForEveryInputKind) {
  const Case c = GetParam();
  Scene scene = testing::SmallBeamScene(c.tets);
  SolverOptions options;
  options.method = c.method;
  options.time_step = c.method == Method::kSemiImplicit ? 2e-4 : 0.01;
  // The check measures its noise floor: the solve tolerance it recommends suffices.
  options.rel_tolerance = problems::RecommendedGradCheckRelTolerance(options.method);
  options.abs_tolerance = 1e-11;  // N, above the rounding floor (~3e-13 here)
  options.backward_rel_tolerance = 1e-13;
  options.max_iterations = 20000;
  options.num_threads = 1;
  Simulator sim(scene, options);
  State initial = sim.RestState();
  // A deformed, moving start so that every term is exercised.
  for (int i = 0; i < initial.x.size() / 3; ++i) {
    initial.x(3 * i + 2) += 0.05 * initial.x(3 * i) * initial.x(3 * i);
    initial.v(3 * i + 1) = 0.2 * initial.x(3 * i);
  }
  const int steps = c.method == Method::kSemiImplicit ? 20 : 4;
  const problems::GradCheckResult result =
      problems::CheckRolloutGradient(scene, options, initial, steps, OneDirection());
  for (const auto& entry : result.inputs) {
    EXPECT_EQ(entry.verdict, problems::CheckVerdict::kPass)
        << ToString(c.method) << " input " << entry.input << ": " << entry.reason;
    EXPECT_GE(entry.margin, 10.0) << ToString(c.method) << " input " << entry.input;  // error and floor <= 1e-5
    EXPECT_GT(entry.directions, 0);
  }
  EXPECT_EQ(result.inputs.size(), 6u);
}

INSTANTIATE_TEST_SUITE_P(AllMethods, SimulatorGradientTest,
                         ::testing::Values(Case{Method::kSemiImplicit, false}, Case{Method::kNewtonCholesky, false},
                                           Case{Method::kNewtonPcg, false}, Case{Method::kPd, false},
                                           Case{Method::kPdLbfgs, false}, Case{Method::kNewtonCholesky, true},
                                           Case{Method::kPd, true}, Case{Method::kPdLbfgs, true}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string name = ToString(info.param.method);
                           for (char& ch : name)
                             if (ch == '-') ch = '_';
                           return name + (info.param.tets ? "_tet" : "_hex");
                         });

}  // namespace
}  // namespace diffpd
