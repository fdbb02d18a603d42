#include "problem_registry.h"

#include "scenes/bouncing_ball.h"
#include "calibration/calibrate_bouncing_ball.h"
#include "calibration/calibrate_cantilever.h"
#include "calibration/calibrate_plant.h"
#include "calibration/calibrate_starfish.h"
#include "control/bunny.h"
#include "scenes/cantilever.h"
#include "control/routing_tendon_opt.h"
#include "scenes/cantilever_plane.h"
#include "diffpd/error.h"
#include "control/locomotion.h"
#include "control/shark_control.h"
#include "control/starfish_control.h"
#include "scenes/rolling_sphere.h"
#include "scenes/routing_tendon.h"

namespace diffpd::problems {

std::vector<std::unique_ptr<Problem>> AllProblems() {
  std::vector<std::unique_ptr<Problem>> all;
  all.push_back(std::make_unique<Cantilever>());
  all.push_back(std::make_unique<FallingCube>());
  all.push_back(std::make_unique<CantileverWithPlane>());
  all.push_back(std::make_unique<RollingSphere>());
  all.push_back(std::make_unique<BouncingBall>());
  // RoutingTendon's forward scene; `diffpd run routing-tendon` optimises its activations.
  all.push_back(std::make_unique<RoutingTendonOpt>());
  all.push_back(std::make_unique<Bunny>());
  all.push_back(std::make_unique<Locomotion>(Locomotion::Body::kTorus));
  all.push_back(std::make_unique<Locomotion>(Locomotion::Body::kQuadruped));
  all.push_back(std::make_unique<Locomotion>(Locomotion::Body::kCow));
  all.push_back(std::make_unique<StarfishControl>());
  all.push_back(std::make_unique<SharkControl>());
  all.push_back(std::make_unique<CantileverCalibration>());
  all.push_back(std::make_unique<PlantCalibration>());
  all.push_back(std::make_unique<BouncingBallCalibration>());
  all.push_back(std::make_unique<StarfishCalibration>());
  return all;
}

std::unique_ptr<Problem> MakeProblem(const std::string& name) {
  std::string valid;
  for (auto& p : AllProblems()) {
    if (p->name() == name) return std::move(p);
    valid += (valid.empty() ? "" : ", ") + p->name();
  }
  throw InvalidInputError("unknown problem '" + name + "': valid problems are " + valid);
}

}  // namespace diffpd::problems
