// A concrete scene with its default run settings and a loss for gradient
// checks. Problems are registered by name in problem_registry.h.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/simulator.h"

namespace diffpd::problems {

struct CommandArgs;  // commands.h

class Problem {
 public:
  virtual ~Problem() = default;
  virtual std::string name() const = 0;
  virtual std::string description() const = 0;  // one line
  virtual Scene MakeScene() const = 0;
  // Initial state of a rollout (defaults to rest).
  virtual State InitialState(const Simulator& sim) const { return sim.RestState(); }
  virtual int default_steps() const = 0;
  virtual double default_time_step() const = 0;
  // Per-step inputs of a default rollout (defaults to no input).
  virtual std::vector<StepInput> Inputs(const Simulator& sim, int steps) const { return std::vector<StepInput>(steps); }
  // `diffpd run <problem>`: a problem that is more than a forward simulation
  // (an optimisation) runs itself and returns the exit code; -1 (the
  // default) means "simulate forward as usual".
  virtual int Run(const CommandArgs& args) const { return -1; }
};

}  // namespace diffpd::problems
