// The cantilever benchmark with an inactive frictional contact plane declared
// (z = -1 m, far below the beam; every free node a candidate), for measuring
// what declaring contact costs when nothing touches: compare
// `diffpd bench cantilever` and `diffpd bench cantilever-plane`.
#pragma once

#include "scenes/cantilever.h"

namespace diffpd::problems {

class CantileverWithPlane : public Cantilever {
 public:
  using Cantilever::Cantilever;
  std::string name() const override { return "cantilever-plane"; }
  std::string description() const override;
  Scene MakeScene() const override;
};

}  // namespace diffpd::problems
