// Muscle strips with a per-element delay line, after the original DiffPD
// swimmers (starfish, water snake): a strip is a chain of elements from its
// root to its tip, each element its own single-element muscle (muscle.h)
// with its own activation; every step a new contraction enters at the root
// and the previous ones move one element towards the tip, so a contraction
// travels along the strip as a wave.
//
// Per strip s with elements j = 0 (root) .. L_s - 1 (tip), contractions c_s
// (the delay line's memory, zero before the first step) and the step's new
// contraction u_s:
//
//   c'_s[0] = u_s,   c'_s[j] = c_s[j - 1] (j >= 1),   activation_j = 1 - c'_s[j],
//
// the contraction at the tip falling off. Muscles in no strip are held at
// rest (activation 1).
#pragma once

#include <vector>

#include "diffpd/scene.h"
#include "diffpd/types.h"

namespace diffpd {

struct MuscleStrip {
  std::vector<int> elements;   // root to tip, indices into the mesh's elements
  Vec3 fiber = Vec3::UnitX();  // rest-frame fibre direction of every element (non-zero)
  double stiffness = 1e5;      // k, Pa (muscle.h)
};

// Appends one single-element Muscle per element of every strip to
// scene->muscles, strip by strip from root to tip, and returns for every
// strip the indices of its muscles (root to tip): the argument of
// MuscleDelayLine. Throws InvalidInputError for an empty strip
// ("AddMuscleStrips: strips[2] has no elements"); the muscles themselves
// are validated by Scene::Validate.
std::vector<std::vector<int>> AddMuscleStrips(Scene* scene, const std::vector<MuscleStrip>& strips);

class MuscleDelayLine {
 public:
  // strip_muscles[s]: strip s's muscles root to tip (indices in [0,
  // num_muscles), each in at most one strip). Throws InvalidInputError for
  // an empty strip, an index out of range or repeated
  // ("MuscleDelayLine: strip 1 lists muscle 7 which is already in a strip").
  MuscleDelayLine(std::vector<std::vector<int>> strip_muscles, int num_muscles);

  int num_strips() const { return static_cast<int>(strips_.size()); }
  int num_muscles() const { return num_muscles_; }
  // The memory: every strip's contractions, strip by strip, root to tip.
  int memory_size() const { return static_cast<int>(slot_muscle_.size()); }
  // The muscle of memory slot i.
  int slot_muscle(int slot) const { return slot_muscle_[slot]; }
  // The first memory slot of strip s.
  int strip_offset(int strip) const { return offsets_[strip]; }

  // One step: the next memory and the activation of every muscle from the
  // memory and the strips' new contractions u (num_strips() entries).
  void Advance(const VectorXd& memory, const VectorXd& contractions, VectorXd* next_memory, VectorXd* activation) const;
  // Reverse mode: from g_activation = dL/d(activation) (num_muscles()
  // entries, or empty) and g_next_memory = dL/d(next memory) (or empty),
  // sets *g_memory = dL/d(memory) and *g_contractions = dL/du.
  void AdvanceVjp(const VectorXd& g_activation, const VectorXd& g_next_memory, VectorXd* g_memory,
                  VectorXd* g_contractions) const;

 private:
  std::vector<std::vector<int>> strips_;
  std::vector<int> offsets_;
  std::vector<int> slot_muscle_;
  int num_muscles_;
};

}  // namespace diffpd
