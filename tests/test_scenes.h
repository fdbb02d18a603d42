// Small scenes shared by the tests.
#pragma once

#include <array>
#include <random>
#include <vector>

#include <Eigen/LU>

#include "diffpd/box_mesh.h"
#include "diffpd/scene.h"
#include "diffpd/simulator.h"

namespace diffpd::testing {

// Box of nx x ny x nz hexes of size (lx, ly, lz) at the origin.
inline Mesh BoxHexMesh(int nx, int ny, int nz, double lx, double ly, double lz) {
  return MakeBoxHexMesh(Eigen::Vector3i(nx, ny, nz), Vec3(lx, ly, lz));
}

// The same box split into 6 tetrahedra per cell (Kuhn subdivision), all
// positively oriented.
inline Mesh BoxTetMesh(int nx, int ny, int nz, double lx, double ly, double lz) {
  const Mesh hex = BoxHexMesh(nx, ny, nz, lx, ly, lz);
  Mesh tet;
  tet.type = ElementType::kTet4;
  tet.vertices = hex.vertices;
  std::vector<std::array<int, 4>> tets;
  // Paths from corner 0 (000) to corner 7 (111) through the cube's edges.
  const int paths[6][4] = {{0, 4, 6, 7}, {0, 4, 5, 7}, {0, 2, 6, 7}, {0, 2, 3, 7}, {0, 1, 5, 7}, {0, 1, 3, 7}};
  for (int e = 0; e < hex.num_elements(); ++e)
    for (const auto& p : paths) {
      std::array<int, 4> t = {hex.elements(p[0], e), hex.elements(p[1], e), hex.elements(p[2], e),
                              hex.elements(p[3], e)};
      Mat3 d;
      for (int c = 0; c < 3; ++c) d.col(c) = tet.vertices.col(t[c + 1]) - tet.vertices.col(t[0]);
      if (d.determinant() < 0) std::swap(t[2], t[3]);
      tets.push_back(t);
    }
  tet.elements.resize(4, static_cast<int>(tets.size()));
  for (size_t e = 0; e < tets.size(); ++e)
    for (int a = 0; a < 4; ++a) tet.elements(a, static_cast<int>(e)) = tets[e][a];
  return tet;
}

// Nodes with x <= tol.
inline std::vector<int> NodesAtXMin(const Mesh& mesh, double tol = 1e-9) {
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.vertices(0, i) <= tol) nodes.push_back(i);
  return nodes;
}

// A small clamped beam with gravity: the default test scene.
inline Scene SmallBeamScene(bool tets = false, std::vector<ElasticEnergy> energies = {ElasticEnergy::kPdCorotated,
                                                                                      ElasticEnergy::kPdVolume}) {
  Scene scene;
  scene.mesh = tets ? BoxTetMesh(3, 2, 2, 0.12, 0.04, 0.04) : BoxHexMesh(4, 2, 2, 0.16, 0.04, 0.04);
  scene.material.youngs_modulus = 2e5;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.energies = std::move(energies);
  scene.gravity = Vec3(0, 0, -9.81);
  FixNodes(&scene, NodesAtXMin(scene.mesh));
  return scene;
}

// Tightly converged settings for derivative tests against finite
// differences: h = 0.01 s (2e-4 s for semi-implicit), one thread.
inline SolverOptions TightOptions(Method method) {
  SolverOptions options;
  options.method = method;
  options.time_step = method == Method::kSemiImplicit ? 2e-4 : 0.01;
  options.rel_tolerance = 1e-12;
  options.abs_tolerance = 1e-11;
  options.backward_rel_tolerance = 1e-13;
  options.max_iterations = 20000;
  options.num_threads = 1;
  // The iteration throughout: the tests compare its gradients (the automatic
  // choice may factorise on some steps).
  options.adjoint_solver = AdjointSolver::kIterative;
  return options;
}

// A deformed, moving start so that every term is exercised.
inline State MovingStart(const Simulator& sim) {
  State s = sim.RestState();
  for (int i = 0; i < s.x.size() / 3; ++i) {
    s.x(3 * i + 2) += 0.05 * s.x(3 * i) * s.x(3 * i);
    s.v(3 * i + 1) = 0.2 * s.x(3 * i);
  }
  return s;
}

// n values uniform in [-scale, scale].
inline VectorXd RandomVector(int n, std::mt19937_64* rng, double scale) {
  std::uniform_real_distribution<double> u(-1, 1);
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = scale * u(*rng);
  return v;
}

// Elements whose centroid has lo <= x < hi.
inline std::vector<int> ElementsWithCentroidX(const Mesh& mesh, double lo, double hi) {
  std::vector<int> out;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    double cx = 0;
    for (int a = 0; a < mesh.elements.rows(); ++a) cx += mesh.vertices(0, mesh.elements(a, e));
    cx /= mesh.elements.rows();
    if (cx >= lo && cx < hi) out.push_back(e);
  }
  return out;
}

// SmallBeamScene with two material regions: region 0 the middle third of the
// beam (softer, E / 5, other nu and density), region 1 the tip third (stiffer,
// other nu and density); the clamped third keeps the base material.
inline Scene TwoRegionBeamScene(bool tets = false) {
  Scene scene = SmallBeamScene(tets);
  const double length = scene.mesh.vertices.row(0).maxCoeff();
  MaterialRegion middle, tip;
  middle.elements = ElementsWithCentroidX(scene.mesh, length / 3, 2 * length / 3);
  middle.material = MaterialParameters{scene.material.youngs_modulus / 5, 0.3, 1.4e3};
  tip.elements = ElementsWithCentroidX(scene.mesh, 2 * length / 3, 2 * length);
  tip.material = MaterialParameters{scene.material.youngs_modulus * 1.5, 0.35, 0.8e3};
  scene.material_regions = {middle, tip};
  return scene;
}

}  // namespace diffpd::testing
