#include "scenes/cantilever_plane.h"

namespace diffpd::problems {

std::string CantileverWithPlane::description() const {
  return Cantilever::description() + ", with an inactive contact plane at z = -1 m";
}

Scene CantileverWithPlane::MakeScene() const {
  Scene scene = Cantilever::MakeScene();
  FrictionalContact plane;
  plane.surface = ContactSurface::Plane(Vec3(0, 0, 1), -1.0);
  std::vector<char> fixed(scene.mesh.num_vertices(), 0);
  for (const int d : scene.dirichlet.dofs) fixed[d / 3] = 1;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (!fixed[i]) plane.nodes.push_back(i);
  scene.frictional_contacts = {plane};
  return scene;
}

}  // namespace diffpd::problems
