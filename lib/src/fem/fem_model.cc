#include "fem/fem_model.h"

#include <cmath>

#include <Eigen/LU>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

// Reference coordinates of Hex8 local node a = 4 i + 2 j + k.
Vec3 HexCorner(int a) { return Vec3(2 * ((a >> 2) & 1) - 1, 2 * ((a >> 1) & 1) - 1, 2 * (a & 1) - 1); }

}  // namespace

FemModel::FemModel(const Mesh& mesh, MassLumping lumping) : mesh_(mesh) {
  ValidateMesh(mesh_);
  k_ = NodesPerElement(mesh_.type);
  q_ = mesh_.type == ElementType::kTet4 ? 1 : 8;
  const int m = num_elements();
  const int n = num_nodes();
  grad_.assign(static_cast<size_t>(m) * q_ * k_ * 3, 0.0);
  volume_.assign(static_cast<size_t>(m) * q_, 0.0);
  unit_mass_ = VectorXd::Zero(n);
  element_unit_mass_.assign(static_cast<size_t>(m) * k_, 0.0);
  shape_values_.assign(q_, std::vector<double>(k_, 0.0));

  if (mesh_.type == ElementType::kTet4) {
    shape_values_[0] = {0.25, 0.25, 0.25, 0.25};
    for (int e = 0; e < m; ++e) {
      Mat3 dm;
      for (int c = 0; c < 3; ++c)
        dm.col(c) = mesh_.vertices.col(mesh_.elements(c + 1, e)) - mesh_.vertices.col(mesh_.elements(0, e));
      const Mat3 inv = dm.inverse();
      Eigen::Map<Eigen::Matrix<double, 4, 3>> g(grad_.data() + static_cast<size_t>(e) * 12);
      g.row(0) = -inv.colwise().sum();
      g.bottomRows<3>() = inv;
      volume_[e] = dm.determinant() / 6.0;
      for (int a = 0; a < 4; ++a) {
        unit_mass_(mesh_.elements(a, e)) += volume_[e] / 4.0;
        element_unit_mass_[4 * static_cast<size_t>(e) + a] = volume_[e] / 4.0;
      }
    }
  } else {
    const double gp = 1.0 / std::sqrt(3.0);
    std::vector<Eigen::Matrix<double, 8, 3>> dn_dxi(8);
    for (int q = 0; q < 8; ++q) {
      const Vec3 xi = HexCorner(q) * gp;
      for (int a = 0; a < 8; ++a) {
        const Vec3 s = HexCorner(a);
        const double f0 = 1 + s(0) * xi(0), f1 = 1 + s(1) * xi(1), f2 = 1 + s(2) * xi(2);
        shape_values_[q][a] = f0 * f1 * f2 / 8.0;
        dn_dxi[q](a, 0) = s(0) * f1 * f2 / 8.0;
        dn_dxi[q](a, 1) = f0 * s(1) * f2 / 8.0;
        dn_dxi[q](a, 2) = f0 * f1 * s(2) / 8.0;
      }
    }
    for (int e = 0; e < m; ++e) {
      Eigen::Matrix<double, 3, 8> xe;
      for (int a = 0; a < 8; ++a) xe.col(a) = mesh_.vertices.col(mesh_.elements(a, e));
      for (int q = 0; q < 8; ++q) {
        const Mat3 jac = xe * dn_dxi[q];  // dX/dxi
        const double det = jac.determinant();
        DIFFPD_CHECK(det > 0, "hex element " << e << " has det J = " << det << " after validation");
        const size_t s = static_cast<size_t>(e) * 8 + q;
        Eigen::Map<Eigen::Matrix<double, 8, 3>> g(grad_.data() + s * 24);
        g = dn_dxi[q] * jac.inverse();
        volume_[s] = det;  // Gauss weight 1
        for (int a = 0; a < 8; ++a) {
          unit_mass_(mesh_.elements(a, e)) += det * shape_values_[q][a];
          element_unit_mass_[8 * static_cast<size_t>(e) + a] += det * shape_values_[q][a];
        }
      }
    }
  }

  if (lumping == MassLumping::kEqualNodes) {
    double total = 0;
    for (int e = 0; e < m; ++e) total += element_volume(e);
    unit_mass_.setConstant(total / m);
  }

  node_offsets_.assign(n + 1, 0);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < k_; ++a) ++node_offsets_[mesh_.elements(a, e) + 1];
  for (int i = 0; i < n; ++i) node_offsets_[i + 1] += node_offsets_[i];
  node_incidence_.assign(node_offsets_[n], 0);
  std::vector<int> fill(node_offsets_.begin(), node_offsets_.end() - 1);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < k_; ++a) node_incidence_[fill[mesh_.elements(a, e)]++] = e * k_ + a;
}

VectorXd FemModel::UnitLumpedMass(const std::vector<int>& part_of_element, int part) const {
  DIFFPD_CHECK(static_cast<int>(part_of_element.size()) == num_elements(),
               "part_of_element has " << part_of_element.size() << " entries for " << num_elements() << " elements");
  VectorXd out = VectorXd::Zero(num_nodes());
  for (int e = 0; e < num_elements(); ++e) {
    if (part_of_element[e] != part) continue;
    for (int a = 0; a < k_; ++a) out(mesh_.elements(a, e)) += element_unit_mass_[static_cast<size_t>(e) * k_ + a];
  }
  return out;
}

double FemModel::element_volume(int e) const {
  double v = 0;
  for (int q = 0; q < q_; ++q) v += volume_[static_cast<size_t>(e) * q_ + q];
  return v;
}

}  // namespace diffpd::internal
