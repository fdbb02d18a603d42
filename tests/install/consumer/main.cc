// Steps a small clamped beam with the installed library and checks that it
// sags under gravity; exits non-zero otherwise.
#include <cstdio>

#include <diffpd/box_mesh.h>
#include <diffpd/simulator.h>

int main() {
  diffpd::Scene scene;
  scene.mesh = diffpd::MakeBoxHexMesh(Eigen::Vector3i(4, 1, 1), diffpd::Vec3(0.2, 0.05, 0.05));
  scene.gravity = diffpd::Vec3(0, 0, -9.81);
  std::vector<int> clamped;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) == 0.0) clamped.push_back(i);
  diffpd::FixNodes(&scene, clamped);
  diffpd::SolverOptions options;
  options.method = diffpd::Method::kPdLbfgs;
  options.rel_tolerance = 1e-4;
  diffpd::Simulator sim(scene, options);
  diffpd::State s = sim.RestState();
  for (int k = 0; k < 5; ++k) s = sim.Step(s, diffpd::StepInput());
  const double tip_z = s.x(s.x.size() - 1) - scene.mesh.vertices(2, scene.mesh.num_vertices() - 1);
  std::printf("consumer: tip moved %.3e m along z\n", tip_z);
  return tip_z < 0 ? 0 : 1;
}
