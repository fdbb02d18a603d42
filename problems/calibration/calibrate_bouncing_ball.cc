#include "calibration/calibrate_bouncing_ball.h"

#include "diffpd/state_forces.h"
#include "diffpd/voxelizer.h"

namespace diffpd::problems {

std::string BouncingBallCalibration::description() const {
  return "recover E and nu of a soft ball from its bounce on the ground (frictional contact, DiffPD Sec. 7.1)";
}

Scene BouncingBallCalibration::MakeScene() const {
  Scene scene = ball_.MakeScene();
  // The same ball on a coarser 6^3 grid (fits run many rollouts).
  const double r = BouncingBall::kRadius;
  scene.mesh =
      VoxelizeSdf([r](const Vec3& p) { return p.norm() - r; }, Vec3::Constant(-r), Eigen::Vector3i(6, 6, 6), 2 * r / 6);
  scene.mesh.vertices.row(2).array() += BouncingBall::kDropHeight - scene.mesh.vertices.row(2).minCoeff();
  scene.frictional_contacts[0].nodes = BoundaryNodes(scene.mesh);
  scene.material = truth();
  return scene;
}

std::vector<Marker> BouncingBallCalibration::Markers(const Mesh& mesh) const {
  std::vector<Marker> markers;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {-1.0, 1.0}) {
      int best = 0;
      for (int i = 1; i < mesh.num_vertices(); ++i)
        if (sign * mesh.vertices(axis, i) > sign * mesh.vertices(axis, best) + 1e-12) best = i;
      bool repeated = false;
      for (const Marker& m : markers) repeated = repeated || m.vertex == best;
      if (!repeated) markers.push_back(Marker{static_cast<int>(markers.size()), best, -1, Vec3::Zero(), 0});
    }
  return markers;
}

std::vector<double> BouncingBallCalibration::CaptureTimes() const {
  std::vector<double> times;
  for (int k = 1; k <= 12; ++k) times.push_back(k / 60.0);
  return times;
}

}  // namespace diffpd::problems
