// Backward and Tangents refuse the same malformed rollouts with the same
// messages (solver/rollout_checks.h): wrong state or input sizes, non-finite
// entries, other settings. A rollout from another mesh once overflowed a
// heap buffer in Backward (smaller mesh) or gave zero gradients (larger).
#include "solver/rollout_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

SolverOptions Options(Method method) {
  SolverOptions options;
  options.method = method;
  options.time_step = method == Method::kSemiImplicit ? 1e-4 : 0.01;
  options.num_threads = 1;
  return options;
}

// The messages of Backward and Tangents on `rollout` ("no exception" if none).
std::pair<std::string, std::string> Messages(Simulator& sim, const Rollout& rollout) {
  std::pair<std::string, std::string> out("no exception", "no exception");
  try {
    sim.Backward(rollout, LossGradient(rollout.num_steps()));
  } catch (const InvalidInputError& e) {
    out.first = e.what();
  }
  try {
    sim.Tangents(rollout, {InputDirection::YoungsModulus()});
  } catch (const InvalidInputError& e) {
    out.second = e.what();
  }
  return out;
}

// A two-step rollout of the beam, corrupted, and the message after the
// caller's name.
struct BadRollout {
  const char* name;
  std::function<void(Rollout*, Method)> corrupt;  // the simulator's method
  std::string message;
};

TEST(RolloutChecksTest, BackwardAndTangentsRefuseMalformedRolloutsAlike) {
  const Scene beam = testing::SmallBeamScene();
  const int n = beam.mesh.num_dofs();
  const std::string dofs = std::to_string(n);
  // The same material, time step and method on other meshes.
  Scene small = beam, large = beam;
  small.mesh = testing::BoxHexMesh(2, 1, 1, 0.08, 0.04, 0.04);
  large.mesh = testing::BoxHexMesh(6, 2, 2, 0.24, 0.04, 0.04);
  small.dirichlet = large.dirichlet = DirichletBoundary();
  const std::vector<BadRollout> cases = {
      {"a rollout of a smaller mesh",
       [&](Rollout* r, Method method) {
         Simulator other(small, Options(method));
         *r = other.Simulate(other.RestState(), std::vector<StepInput>(2));
       },
       "the rollout's state 0 has x with 36 entries, expected " + dofs + " (3 x number of nodes)"},
      {"a rollout of a larger mesh",
       [&](Rollout* r, Method method) {
         Simulator other(large, Options(method));
         *r = other.Simulate(other.RestState(), std::vector<StepInput>(2));
       },
       "the rollout's state 0 has x with 189 entries, expected " + dofs + " (3 x number of nodes)"},
      {"a missing state", [](Rollout* r, Method) { r->states.pop_back(); },
       "the rollout has 2 states for 2 inputs (needs one more state than inputs)"},
      {"a short velocity", [](Rollout* r, Method) { r->states[2].v.resize(6); },
       "the rollout's state 2 has v with 6 entries, expected " + dofs + " (3 x number of nodes)"},
      {"a NaN position", [](Rollout* r, Method) { r->states[1].x(4) = std::nan(""); },
       "the rollout's state 1 has a non-finite entry in x"},
      {"a short external force", [](Rollout* r, Method) { r->inputs[1].external_force = VectorXd::Ones(3); },
       "the rollout's input 1 has external_force with 3 entries, expected " + dofs + " (3 x number of nodes)"},
      {"an infinite external force",
       [n](Rollout* r, Method) {
         r->inputs[0].external_force = VectorXd::Zero(n);
         r->inputs[0].external_force(0) = INFINITY;
       },
       "the rollout's input 0 has a non-finite entry in external_force"},
      {"activations without muscles", [](Rollout* r, Method) { r->inputs[0].activation = VectorXd::Ones(2); },
       "the rollout's input 0: activation has 2 entries, expected 0 (one per muscle)"},
      {"another time step", [](Rollout* r, Method) { r->options.time_step *= 2; },
       "the rollout was made with another time step (<2h> s) than the simulator's current one (<h> s)"},
      {"another material", [](Rollout* r, Method) { r->material.density = 2e3; },
       "the rollout was made with another material (E = 200000 Pa, nu = 0.4, rho = 2000 kg/m^3) than the "
       "simulator's current one (E = 200000 Pa, nu = 0.4, rho = 1000 kg/m^3)"},
  };
  for (Method method : {Method::kPd, Method::kSemiImplicit}) {
    Simulator sim(beam, Options(method));
    const Rollout good = sim.Simulate(sim.RestState(), std::vector<StepInput>(2));
    EXPECT_EQ(Messages(sim, good), std::make_pair(std::string("no exception"), std::string("no exception")));
    for (const BadRollout& c : cases) {
      Rollout bad = good;
      c.corrupt(&bad, method);
      const auto [backward, tangents] = Messages(sim, bad);
      // <h> and <2h> in a message: the method's time step and twice it.
      std::string message = c.message;
      for (const auto& [key, factor] : {std::pair<std::string, double>{"<h>", 1.0}, {"<2h>", 2.0}}) {
        std::ostringstream value;
        value << factor * sim.options().time_step;
        if (const size_t at = message.find(key); at != std::string::npos) message.replace(at, key.size(), value.str());
      }
      EXPECT_EQ(backward, "Backward: " + message) << c.name << ", " << ToString(method);
      EXPECT_EQ(tangents, "Tangents: " + message) << c.name << ", " << ToString(method);
    }
  }
}

}  // namespace
}  // namespace diffpd
