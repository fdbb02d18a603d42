// Validation of a scene's optional terms (internal): muscles, frictional and
// penalty contact, hydrodynamics, linear damping. Called by Scene::Validate
// after the mesh, material and Dirichlet checks.
#pragma once

#include "diffpd/scene.h"

namespace diffpd::internal {

// Throws InvalidInputError naming the first invalid input, its value and the
// valid range (the messages are listed in muscle.h, contact.h, state_forces.h).
void ValidateOptionalTerms(const Scene& scene);

}  // namespace diffpd::internal
