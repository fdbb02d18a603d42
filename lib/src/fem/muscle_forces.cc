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
    : fem_(fem), k_(fem.nodes_per_element()), num_muscles_(static_cast<int>(muscles.size())) {
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
        for (int a = 0; a < k_; ++a) coefficients_.push_back(g.row(a).dot(fiber));
      }
    }
  }
}

double MuscleForces::Activation(const VectorXd& activation, int muscle) const {
  return activation.size() == 0 ? 1.0 : activation(muscle);
}

Vec3 MuscleForces::Feature(const VectorXd& x, size_t s) const {
  const double* c = coefficients(s);
  Vec3 u = Vec3::Zero();
  for (int a = 0; a < k_; ++a) u += c[a] * x.segment<3>(3 * fem_.mesh().elements(a, samples_[s].element));
  return u;
}

double MuscleForces::AddEnergyAndGradient(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const {
  double energy = 0;
  for (size_t s = 0; s < samples_.size(); ++s) {
    const Sample& sm = samples_[s];
    const double a = Activation(activation, sm.muscle);
    const Vec3 u = Feature(x, s);
    const double stretch = u.norm() - a;
    energy += 0.5 * sm.weight * stretch * stretch;
    if (!grad) continue;
    const Vec3 force = sm.weight * (u - a * Direction(u, sm.fiber));
    const double* c = coefficients(s);
    for (int k = 0; k < k_; ++k) grad->segment<3>(3 * fem_.mesh().elements(k, sm.element)) += c[k] * force;
  }
  return energy;
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

void MuscleForces::AddHessianProduct(const VectorXd& x, const VectorXd& activation, const VectorXd& z,
                                     VectorXd* out) const {
  for (size_t s = 0; s < samples_.size(); ++s) {
    const Sample& sm = samples_[s];
    const Mat3 h = SampleHessian(Feature(x, s), sm.fiber, sm.weight, Activation(activation, sm.muscle), false);
    const Vec3 dz = h * Feature(z, s);
    const double* c = coefficients(s);
    for (int k = 0; k < k_; ++k) out->segment<3>(3 * fem_.mesh().elements(k, sm.element)) += c[k] * dz;
  }
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
