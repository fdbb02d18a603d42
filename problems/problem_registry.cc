#include "problem_registry.h"

#include "control/shark_control.h"
#include "control/starfish_control.h"
#include "diffpd/error.h"
#include "scenes/bouncing_ball.h"
#include "scenes/cantilever.h"
#include "scenes/cantilever_plane.h"
#include "scenes/rolling_sphere.h"
#include "scenes/routing_tendon.h"
#if DIFFPD_WITH_CERES
#include "calibration/calibrate_bouncing_ball.h"
#include "calibration/calibrate_cantilever.h"
#include "calibration/calibrate_plant.h"
#include "calibration/calibrate_starfish.h"
#endif
#if DIFFPD_WITH_IPOPT
#include "control/bunny.h"
#include "control/locomotion.h"
#include "control/routing_tendon_opt.h"
#endif

namespace diffpd::problems {

std::vector<std::unique_ptr<Problem>> AllProblems() {
  std::vector<std::unique_ptr<Problem>> all;
  all.push_back(std::make_unique<Cantilever>());
  all.push_back(std::make_unique<FallingCube>());
  all.push_back(std::make_unique<CantileverWithPlane>());
  all.push_back(std::make_unique<RollingSphere>());
  all.push_back(std::make_unique<BouncingBall>());
#if DIFFPD_WITH_IPOPT
  // RoutingTendon's forward scene; `diffpd run routing-tendon` optimises its activations.
  all.push_back(std::make_unique<RoutingTendonOpt>());
  all.push_back(std::make_unique<Bunny>());
  all.push_back(std::make_unique<Locomotion>(Locomotion::Body::kTorus));
  all.push_back(std::make_unique<Locomotion>(Locomotion::Body::kQuadruped));
  all.push_back(std::make_unique<Locomotion>(Locomotion::Body::kCow));
#else
  all.push_back(std::make_unique<RoutingTendon>());  // the forward scene only
#endif
  all.push_back(std::make_unique<StarfishControl>());
  all.push_back(std::make_unique<SharkControl>());
#if DIFFPD_WITH_CERES
  all.push_back(std::make_unique<CantileverCalibration>());
  all.push_back(std::make_unique<PlantCalibration>());
  all.push_back(std::make_unique<BouncingBallCalibration>());
  all.push_back(std::make_unique<StarfishCalibration>());
#endif
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
