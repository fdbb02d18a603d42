// Finite-element discretisation of a mesh (internal): per-sample shape
// function gradients and volumes, lumped mass, node-to-element adjacency.
//
// A "sample" is one quadrature point of one element: 1 per Tet4 (centroid,
// exact for linear tets), 8 per Hex8 (2x2x2 Gauss points, weights 1 on the
// reference cube [-1,1]^3). Sample s = e * Q + q. At sample s the deformation
// gradient is F = X_e * grad(s), X_e the 3 x K nodal positions of element e
// and grad(s) the K x 3 matrix of dN_a/dX.
#pragma once

#include <vector>

#include "diffpd/mesh.h"
#include "diffpd/scene.h"
#include "diffpd/types.h"

namespace diffpd::internal {

class FemModel {
 public:
  // Validates the mesh (throws InvalidInputError) and precomputes everything.
  // `lumping` sets unit_lumped_mass() (Scene::mass_lumping); UnitLumpedMass
  // of parts is the integral of N_a either way (kEqualNodes has one part).
  explicit FemModel(const Mesh& mesh, MassLumping lumping = MassLumping::kLumped);

  const Mesh& mesh() const { return mesh_; }
  int num_nodes() const { return mesh_.num_vertices(); }
  int num_elements() const { return mesh_.num_elements(); }
  int nodes_per_element() const { return k_; }
  int samples_per_element() const { return q_; }
  int num_samples() const { return num_elements() * q_; }

  // K x 3 shape-function gradients at sample s (column-major, K*3 doubles).
  const double* grad(int s) const { return grad_.data() + static_cast<size_t>(s) * k_ * 3; }
  // Rest volume carried by sample s (quadrature weight x det J), m^3.
  double sample_volume(int s) const { return volume_[s]; }
  // The rest volumes of samples s, s + 1, ... (contiguous, m^3).
  const double* sample_volumes(int s) const { return volume_.data() + s; }
  // Rest volume of element e, m^3.
  double element_volume(int e) const;
  // Mass per node for unit density (m^3): the integral of N_a over the mesh,
  // or the mean element volume at every node (MassLumping::kEqualNodes).
  const VectorXd& unit_lumped_mass() const { return unit_mass_; }
  // The same restricted to the elements e with part_of_element[e] == part
  // (num_elements entries; see scene/material_regions.h), summed in element
  // order (n, m^3). The parts' vectors add up to unit_lumped_mass().
  VectorXd UnitLumpedMass(const std::vector<int>& part_of_element, int part) const;

  // Node -> (element, local index) adjacency in CSR form, for parallel gathers.
  const std::vector<int>& node_offsets() const { return node_offsets_; }
  const std::vector<int>& node_incidences() const { return node_incidence_; }  // e * K + a

  // Shape function values N_a at sample q of an element (K values).
  const std::vector<double>& shape_values(int q) const { return shape_values_[q]; }

 private:
  Mesh mesh_;
  int k_ = 0;
  int q_ = 0;
  std::vector<double> grad_;
  std::vector<double> volume_;
  VectorXd unit_mass_;
  std::vector<double> element_unit_mass_;  // K per element: element e's share of node a's unit mass
  std::vector<int> node_offsets_;
  std::vector<int> node_incidence_;
  std::vector<std::vector<double>> shape_values_;
};

// Deformation gradient at a sample from the element's nodal positions.
template <int K>
inline Mat3 DeformationGradient(const Eigen::Matrix<double, 3, K>& xe, const double* grad) {
  return xe * Eigen::Map<const Eigen::Matrix<double, K, 3>>(grad);
}

// Gathers the 3 x K nodal values of element e from a 3n vector.
template <int K>
inline Eigen::Matrix<double, 3, K> GatherElement(const Mesh& mesh, const VectorXd& x, int e) {
  Eigen::Matrix<double, 3, K> xe;
  for (int a = 0; a < K; ++a) xe.col(a) = x.segment<3>(3 * mesh.elements(a, e));
  return xe;
}

}  // namespace diffpd::internal
