#include "diffpd/muscle_strip.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd {

std::vector<std::vector<int>> AddMuscleStrips(Scene* scene, const std::vector<MuscleStrip>& strips) {
  std::vector<std::vector<int>> out;
  for (size_t s = 0; s < strips.size(); ++s)
    if (strips[s].elements.empty()) {
      std::ostringstream msg;
      msg << "AddMuscleStrips: strips[" << s << "] has no elements";
      throw InvalidInputError(msg.str());
    }
  for (const MuscleStrip& strip : strips) {
    std::vector<int> muscles;
    for (const int e : strip.elements) {
      Muscle m;
      m.elements = {e};
      m.fibers = {strip.fiber};
      m.stiffness = strip.stiffness;
      muscles.push_back(static_cast<int>(scene->muscles.size()));
      scene->muscles.push_back(std::move(m));
    }
    out.push_back(std::move(muscles));
  }
  return out;
}

MuscleDelayLine::MuscleDelayLine(std::vector<std::vector<int>> strip_muscles, int num_muscles)
    : strips_(std::move(strip_muscles)), num_muscles_(num_muscles) {
  std::vector<char> used(num_muscles > 0 ? num_muscles : 0, 0);
  for (size_t s = 0; s < strips_.size(); ++s) {
    if (strips_[s].empty()) {
      std::ostringstream msg;
      msg << "MuscleDelayLine: strip " << s << " has no muscles";
      throw InvalidInputError(msg.str());
    }
    offsets_.push_back(static_cast<int>(slot_muscle_.size()));
    for (const int m : strips_[s]) {
      std::ostringstream msg;
      if (m < 0 || m >= num_muscles) {
        msg << "MuscleDelayLine: strip " << s << " lists muscle " << m << ", out of range [0, " << num_muscles << ")";
        throw InvalidInputError(msg.str());
      }
      if (used[m]) {
        msg << "MuscleDelayLine: strip " << s << " lists muscle " << m << " which is already in a strip";
        throw InvalidInputError(msg.str());
      }
      used[m] = 1;
      slot_muscle_.push_back(m);
    }
  }
}

void MuscleDelayLine::Advance(const VectorXd& memory, const VectorXd& contractions, VectorXd* next_memory,
                              VectorXd* activation) const {
  DIFFPD_CHECK(memory.size() == memory_size(), "MuscleDelayLine: memory has " << memory.size() << " entries");
  DIFFPD_CHECK(contractions.size() == num_strips(),
               "MuscleDelayLine: contractions have " << contractions.size() << " entries");
  next_memory->resize(memory_size());
  for (int s = 0; s < num_strips(); ++s) {
    const int o = offsets_[s], len = static_cast<int>(strips_[s].size());
    (*next_memory)(o) = contractions(s);
    for (int j = 1; j < len; ++j) (*next_memory)(o + j) = memory(o + j - 1);
  }
  *activation = VectorXd::Ones(num_muscles_);
  for (int i = 0; i < memory_size(); ++i) (*activation)(slot_muscle_[i]) = 1.0 - (*next_memory)(i);
}

void MuscleDelayLine::AdvanceVjp(const VectorXd& g_activation, const VectorXd& g_next_memory, VectorXd* g_memory,
                                 VectorXd* g_contractions) const {
  // dL/d(next memory) in total: directly, and through activation = 1 - next.
  VectorXd g_next = g_next_memory.size() ? g_next_memory : VectorXd::Zero(memory_size());
  if (g_activation.size())
    for (int i = 0; i < memory_size(); ++i) g_next(i) -= g_activation(slot_muscle_[i]);
  *g_memory = VectorXd::Zero(memory_size());
  g_contractions->resize(num_strips());
  for (int s = 0; s < num_strips(); ++s) {
    const int o = offsets_[s], len = static_cast<int>(strips_[s].size());
    (*g_contractions)(s) = g_next(o);
    for (int j = 1; j < len; ++j) (*g_memory)(o + j - 1) = g_next(o + j);
  }
}

}  // namespace diffpd
