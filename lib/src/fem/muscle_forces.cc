#include "fem/muscle_forces.h"

#include <cmath>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

constexpr double kDegenerateFeature = 1e-12;

// Unit direction of the feature u, or the fibre itself where u vanishes.
Vec3 Direction(const Vec3& u, const Vec3& fiber) {
  const double norm = u.norm();
  return norm < kDegenerateFeature ? fiber : Vec3(u / norm);
}

// The 3x3 factor H of the sample Hessian c c^T (x) H (weight included).
Mat3 SampleHessian(const Vec3& u, const Vec3& fiber, double weight, double a, bool project_spd) {
  const double norm = u.norm();
  if (norm < kDegenerateFeature) return weight * Mat3::Identity();
  const Vec3 d = u / norm;
  double perp = 1.0 - a / norm;
  if (project_spd && perp < 0) perp = 0;
  return weight * (perp * Mat3::Identity() + (1.0 - perp) * d * d.transpose());
}

}  // namespace

MuscleForces::MuscleForces(const FemModel& fem, const std::vector<Muscle>& muscles)
    : fem_(fem),
      k_(fem.nodes_per_element()),
      q_(fem.samples_per_element()),
      num_muscles_(static_cast<int>(muscles.size())) {
  const int q_per = fem.samples_per_element();
  for (int j = 0; j < num_muscles_; ++j) {
    const Muscle& muscle = muscles[j];
    for (size_t t = 0; t < muscle.elements.size(); ++t) {
      const int e = muscle.elements[t];
      const Vec3 fiber = (muscle.fibers.size() == 1 ? muscle.fibers[0] : muscle.fibers[t]).normalized();
      for (int q = 0; q < q_per; ++q) {
        const int s = e * q_per + q;
        samples_.push_back(Sample{j, e, muscle.stiffness * fem.sample_volume(s), fiber});
        const Eigen::Map<const Eigen::MatrixXd> g(fem.grad(s), k_, 3);
        for (int a = 0; a < k_; ++a) {
          coefficients_.push_back(g.row(a).dot(fiber));
          nodes_.push_back(fem.mesh().elements(a, e));
        }
      }
    }
  }
}

double MuscleForces::Activation(const VectorXd& activation, int muscle) const {
  return activation.size() == 0 ? 1.0 : activation(muscle);
}

Vec3 MuscleForces::Feature(const VectorXd& x, size_t s) const {
  const double* c = coefficients(s);
  const int* nd = nodes(s);
  Vec3 u = Vec3::Zero();
  for (int a = 0; a < k_; ++a) u += c[a] * x.segment<3>(3 * nd[a]);
  return u;
}

namespace {

// sum_a c_a x_{node_a} for K nodes (K = 0: k nodes, a runtime count).
template <int K>
Vec3 FeatureOf(const double* x, const int* nodes, const double* c, int k) {
  const int count = K > 0 ? K : k;
  double u0 = 0, u1 = 0, u2 = 0;
  for (int a = 0; a < count; ++a) {
    const double* p = x + 3 * nodes[a];
    u0 += c[a] * p[0];
    u1 += c[a] * p[1];
    u2 += c[a] * p[2];
  }
  return Vec3(u0, u1, u2);
}

// out_{node_a} += c_a f.
template <int K>
void Scatter(const Vec3& f, const int* nodes, const double* c, int k, double* out) {
  const int count = K > 0 ? K : k;
  for (int a = 0; a < count; ++a) {
    double* p = out + 3 * nodes[a];
    p[0] += c[a] * f(0);
    p[1] += c[a] * f(1);
    p[2] += c[a] * f(2);
  }
}

}  // namespace

template <int K>
double MuscleForces::EnergyAndGradientImpl(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const {
  double energy = 0;
  for (size_t s = 0; s < samples_.size(); ++s) {
    const Sample& sm = samples_[s];
    const double a = Activation(activation, sm.muscle);
    const Vec3 u = FeatureOf<K>(x.data(), nodes(s), coefficients(s), k_);
    const double stretch = u.norm() - a;
    energy += 0.5 * sm.weight * stretch * stretch;
    if (grad) Scatter<K>(sm.weight * (u - a * Direction(u, sm.fiber)), nodes(s), coefficients(s), k_, grad->data());
  }
  return energy;
}

namespace {

using Mat38 = Eigen::Matrix<double, 3, 8>;
using Mat88 = Eigen::Matrix<double, 8, 8>;

Mat38 Gather(const double* x, const int* nodes) {
  Mat38 out;
  for (int a = 0; a < 8; ++a) out.col(a) = Eigen::Map<const Vec3>(x + 3 * nodes[a]);
  return out;
}

void ScatterAdd(const Mat38& f, const int* nodes, double* out) {
  for (int a = 0; a < 8; ++a) Eigen::Map<Vec3>(out + 3 * nodes[a]) += f.col(a);
}

}  // namespace

double MuscleForces::HexEnergyAndGradient(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const {
  double energy = 0;
  for (size_t g = 0; g < samples_.size(); g += 8) {
    const Eigen::Map<const Mat88> c(coefficients(g));  // column q: sample q's c_a
    const int* nd = nodes(g);
    const Mat38 u = Gather(x.data(), nd) * c;
    Mat38 f;
    for (int q = 0; q < 8; ++q) {
      const Sample& sm = samples_[g + q];
      const double a = Activation(activation, sm.muscle);
      const double stretch = u.col(q).norm() - a;
      energy += 0.5 * sm.weight * stretch * stretch;
      f.col(q) = sm.weight * (u.col(q) - a * Direction(u.col(q), sm.fiber));
    }
    if (grad) ScatterAdd(f * c.transpose(), nd, grad->data());
  }
  return energy;
}

void MuscleForces::HexHessianProduct(const VectorXd& x, const VectorXd& activation, const VectorXd& z,
                                     VectorXd* out) const {
  for (size_t g = 0; g < samples_.size(); g += 8) {
    const Eigen::Map<const Mat88> c(coefficients(g));
    const int* nd = nodes(g);
    const Mat38 u = Gather(x.data(), nd) * c, dz = Gather(z.data(), nd) * c;
    Mat38 h;
    for (int q = 0; q < 8; ++q) {
      const Sample& sm = samples_[g + q];
      const double norm = u.col(q).norm();
      if (norm < kDegenerateFeature) {
        h.col(q) = sm.weight * dz.col(q);
      } else {
        const Vec3 d = u.col(q) / norm;
        const double perp = 1.0 - Activation(activation, sm.muscle) / norm;
        h.col(q) = sm.weight * (perp * dz.col(q) + (1.0 - perp) * d.dot(dz.col(q)) * d);
      }
    }
    ScatterAdd(h * c.transpose(), nd, out->data());
  }
}

double MuscleForces::AddEnergyAndGradient(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const {
  if (hex_groups()) return HexEnergyAndGradient(x, activation, grad);
  if (k_ == 8) return EnergyAndGradientImpl<8>(x, activation, grad);
  if (k_ == 4) return EnergyAndGradientImpl<4>(x, activation, grad);
  return EnergyAndGradientImpl<0>(x, activation, grad);
}

void MuscleForces::AddElementHessians(const VectorXd& x, const VectorXd& activation, bool project_spd,
                                      std::vector<double>* blocks) const {
  const int nb = 3 * k_;
  for (size_t s = 0; s < samples_.size(); ++s) {
    const Sample& sm = samples_[s];
    const Mat3 h = SampleHessian(Feature(x, s), sm.fiber, sm.weight, Activation(activation, sm.muscle), project_spd);
    const double* c = coefficients(s);
    double* ke = blocks->data() + static_cast<size_t>(sm.element) * nb * nb;
    for (int b = 0; b < k_; ++b)
      for (int a = 0; a < k_; ++a) {
        const double cc = c[a] * c[b];
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) ke[(3 * b + j) * nb + 3 * a + i] += cc * h(i, j);
      }
  }
}

template <int K>
void MuscleForces::HessianProductImpl(const VectorXd& x, const VectorXd& activation, const VectorXd& z,
                                      VectorXd* out) const {
  for (size_t s = 0; s < samples_.size(); ++s) {
    const Sample& sm = samples_[s];
    const double* c = coefficients(s);
    const int* nd = nodes(s);
    const Vec3 u = FeatureOf<K>(x.data(), nd, c, k_);
    const Vec3 dz = FeatureOf<K>(z.data(), nd, c, k_);
    // SampleHessian(u) dz without forming the matrix.
    const double norm = u.norm();
    Vec3 h;
    if (norm < kDegenerateFeature) {
      h = sm.weight * dz;
    } else {
      const Vec3 d = u / norm;
      const double perp = 1.0 - Activation(activation, sm.muscle) / norm;
      h = sm.weight * (perp * dz + (1.0 - perp) * d.dot(dz) * d);
    }
    Scatter<K>(h, nd, c, k_, out->data());
  }
}

void MuscleForces::AddHessianProduct(const VectorXd& x, const VectorXd& activation, const VectorXd& z,
                                     VectorXd* out) const {
  if (hex_groups()) return HexHessianProduct(x, activation, z, out);
  if (k_ == 8) return HessianProductImpl<8>(x, activation, z, out);
  if (k_ == 4) return HessianProductImpl<4>(x, activation, z, out);
  HessianProductImpl<0>(x, activation, z, out);
}

VectorXd MuscleForces::ActivationGradient(const VectorXd& x, const VectorXd& activation, const VectorXd& z) const {
  VectorXd out = VectorXd::Zero(num_muscles_);
  for (size_t s = 0; s < samples_.size(); ++s) {
    const Sample& sm = samples_[s];
    const Vec3 u = Feature(x, s);
    out(sm.muscle) += sm.weight * Direction(u, sm.fiber).dot(Feature(z, s));
  }
  return out;
}

void MuscleForces::AddPdTriplets(std::vector<Eigen::Triplet<double>>* triplets) const {
  for (size_t s = 0; s < samples_.size(); ++s) {
    const Sample& sm = samples_[s];
    const double* c = coefficients(s);
    for (int a = 0; a < k_; ++a)
      for (int b = 0; b < k_; ++b)
        triplets->emplace_back(fem_.mesh().elements(a, sm.element), fem_.mesh().elements(b, sm.element),
                               sm.weight * c[a] * c[b]);
  }
}

}  // namespace diffpd::internal
