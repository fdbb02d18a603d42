#include "fem/elastic_forces.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>

#include <Eigen/Eigenvalues>

#include "diffpd/error.h"
#include "fem/packed_element_matrices.h"
#include "fem/pd_hex_kernel.h"
#include "material/density_kernels.h"
#include "material/svd3.h"

namespace diffpd::internal {
namespace {

constexpr int kMinParallelElements = 256;
constexpr int kMaxSamplesPerElement = 8;  // hexahedra's 2 x 2 x 2 Gauss points

// Runs body(e) for e in [0, m) in parallel and rethrows the first exception
// after the loop (exceptions must not leave an OpenMP region).
template <class Body>
void ParallelForElements(int m, int threads, Body&& body, int min_parallel = kMinParallelElements) {
  std::exception_ptr error;
  std::mutex error_mutex;
  // Small meshes run serially: a parallel region costs more than it saves.
  const int nt = threads > 0 ? threads : 0;
#pragma omp parallel for schedule(static) num_threads(nt) if (nt != 1 && m >= min_parallel)
  for (int e = 0; e < m; ++e) {
    try {
      body(e);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

// Runs body(e0, count) over groups of consecutive elements whose quadrature
// points fill one SVD batch (16 tetrahedra of 1 point, or 2 hexahedra of 8),
// in parallel over groups.
template <class Body>
void ParallelForSampleBatches(int num_elements, int samples_per_element, int threads, Body&& body) {
  const int per = std::max(1, kSvdBatch / samples_per_element);
  const int groups = (num_elements + per - 1) / per;
  ParallelForElements(
      groups, threads, [&](int g) { body(g * per, std::min(per, num_elements - g * per)); },
      std::max(1, kMinParallelElements / per));
}

// ke += vol dF/dx^T dP dF/dx for one sample, with the structure of dF/dx
// used: F(i, j) = sum_a x(i, a) G(a, j), so dF(i, j)/dx(k, b) = delta_ik G(b, j)
// and ke(3a + i, 3b + k) += vol sum_{j,l} G(a, j) dP(i + 3j, k + 3l) G(b, l):
// 27 (3K + K^2) multiply-adds, against 243 K + 81 K^2 for the dense products
// with the 9 x 3K matrix dF/dx.
// With kUpper only the node blocks (a, b >= a) are accumulated (the packed
// layout's; 27 K (K + 1) / 2 instead of 27 K^2 in the second stage).
template <int K, bool kUpper = false>
inline void AddSampleStiffness(const double* g, double vol, const Mat9& dP,
                               Eigen::Map<Eigen::Matrix<double, 3 * K, 3 * K>>& ke) {
  const Eigen::Map<const Eigen::Matrix<double, K, 3>> G(g);
  Eigen::Matrix<double, 9, 3 * K> t;  // t(r, 3b + k) = vol sum_l dP(r, k + 3l) G(b, l)
  for (int b = 0; b < K; ++b)
    t.template middleCols<3>(3 * b) = (vol * G(b, 0)) * dP.middleCols<3>(0) + (vol * G(b, 1)) * dP.middleCols<3>(3) +
                                      (vol * G(b, 2)) * dP.middleCols<3>(6);
  if (kUpper) {
    for (int b = 0; b < K; ++b)
      for (int a = 0; a <= b; ++a)
        ke.template block<3, 3>(3 * a, 3 * b) += G(a, 0) * t.template block<3, 3>(0, 3 * b) +
                                                 G(a, 1) * t.template block<3, 3>(3, 3 * b) +
                                                 G(a, 2) * t.template block<3, 3>(6, 3 * b);
    return;
  }
  for (int a = 0; a < K; ++a)
    ke.template middleRows<3>(3 * a) += G(a, 0) * t.template middleRows<3>(0) + G(a, 1) * t.template middleRows<3>(3) +
                                        G(a, 2) * t.template middleRows<3>(6);
}

// Per part p, the sums over its elements (in element order) of the
// per-element dots; throws SolverError(kNonFinite) for a non-finite sum.
void SumPartDots(const std::vector<double>& element_mu, const std::vector<double>& element_lambda,
                 const std::vector<int>& part_of_element, int num_parts, VectorXd* dmu, VectorXd* dlambda) {
  *dmu = VectorXd::Zero(num_parts);
  *dlambda = VectorXd::Zero(num_parts);
  for (size_t e = 0; e < element_mu.size(); ++e) {
    const int p = part_of_element.empty() ? 0 : part_of_element[e];
    (*dmu)(p) += element_mu[e];
    (*dlambda)(p) += element_lambda[e];
  }
  if (!dmu->allFinite() || !dlambda->allFinite())
    throw SolverError(SolverStatus::kNonFinite, "the elastic Lame-parameter derivatives are not finite");
}

}  // namespace

bool AnyNeedsSvd(const std::vector<ElasticEnergy>& energies) {
  bool need_svd = false;
  for (const ElasticEnergy energy : energies) need_svd = need_svd || NeedsSvd(energy);
  return need_svd;
}

double EvaluateDensity(const std::vector<ElasticEnergy>& energies, const Mat3& F, double mu, double lambda,
                       Mat3* stress, Mat9* dstress, Mat3* v_cache) {
  Svd3 svd;
  if (AnyNeedsSvd(energies)) {
    svd = v_cache ? ComputeSvd3(F, *v_cache) : ComputeSvd3(F);
    if (v_cache) *v_cache = svd.V;
  }
  return EvaluateDensity(energies, F, svd, mu, lambda, stress, dstress);
}

double EvaluateDensity(const std::vector<ElasticEnergy>& energies, const Mat3& F, const Svd3& svd, double mu,
                       double lambda, Mat3* stress, Mat9* dstress, const VolumeProjection* volume) {
  double psi = 0;
  if (stress) stress->setZero();
  if (dstress) dstress->setZero();
  Mat3 p;
  // The singular-value energies' differentials share U and V: their
  // coefficients add up and are assembled once.
  IsotropicDifferentialCoefficients sum;
  bool any_svd = false;
  for (const ElasticEnergy energy : energies) {
    psi += EnergyAndStress(energy, F, svd, mu, lambda, stress ? &p : nullptr, volume);
    if (stress) *stress += p;
    if (!dstress) continue;
    if (!NeedsSvd(energy)) {
      *dstress += internal::StressDifferential(energy, F, svd, mu, lambda);
      continue;
    }
    sum += StressDifferentialCoefficients(energy, svd, mu, lambda, volume);
    any_svd = true;
  }
  if (any_svd) *dstress += AssembleIsotropicDifferential(svd, sum);
  return psi;
}

ElasticForces::ElasticForces(const FemModel& fem, std::vector<ElasticEnergy> energies)
    : fem_(fem), energies_(std::move(energies)) {
  for (const ElasticEnergy e : energies_) all_projective_ = all_projective_ && IsProjective(e);
  needs_svd_ = AnyNeedsSvd(energies_);
  coefficient_form_ = !energies_.empty();
  for (const ElasticEnergy e : energies_) coefficient_form_ = coefficient_form_ && NeedsSvd(e);
  for (const ElasticEnergy e : energies_) {
    rotation_terms_ += e == ElasticEnergy::kPdCorotated;
    volume_terms_ += e == ElasticEnergy::kPdVolume;
  }
  needs_volume_ = volume_terms_ > 0;
  element_buffer_.assign(static_cast<size_t>(fem_.num_elements()) * 3 * fem_.nodes_per_element(), 0.0);
  element_energy_.assign(fem_.num_elements(), 0.0);
  v_cache_.assign(fem_.num_samples(), Mat3::Identity());
  const bool pd_only = !energies_.empty() && rotation_terms_ + volume_terms_ == static_cast<int>(energies_.size());
  pd_hex_kernel_ = pd_only && fem_.nodes_per_element() == 8 && fem_.samples_per_element() == 8;
  if (pd_hex_kernel_) {
    hex_lane_gradients_.resize(static_cast<size_t>(fem_.num_elements()) * kHexLaneGradients);
    for (int e = 0; e < fem_.num_elements(); ++e) {
      double* out = hex_lane_gradients_.data() + static_cast<size_t>(e) * kHexLaneGradients;
      for (int l = 0; l < 8; ++l) {
        const double* g = fem_.grad(8 * e + l);  // 8 x 3, column-major
        for (int k = 0; k < 24; ++k) out[k * 8 + l] = g[k];
      }
    }
  }
}

void ElasticForces::ResetWarmStart() { std::fill(v_cache_.begin(), v_cache_.end(), Mat3::Identity()); }

double ElasticForces::PdWeight(double mu, double lambda) const {
  double w = 0;
  for (const ElasticEnergy e : energies_) {
    if (e == ElasticEnergy::kPdCorotated)
      w += 2 * mu;
    else if (e == ElasticEnergy::kPdVolume)
      w += lambda;
    else
      w += 2 * mu + lambda;
  }
  return w;
}

void ElasticForces::GatherElementBuffer(VectorXd* out, int threads) const {
  out->resize(3 * fem_.num_nodes());
  GatherBuffer(element_buffer_.data(), out->data(), threads);
}

void ElasticForces::GatherBuffer(const double* buffer, double* out, int threads) const {
  const int n = fem_.num_nodes();
  const auto& off = fem_.node_offsets();
  const auto& inc = fem_.node_incidences();
  const int nt = threads > 0 ? threads : 0;
#pragma omp parallel for schedule(static) num_threads(nt) if (nt != 1 && n >= 4 * kMinParallelElements)
  for (int i = 0; i < n; ++i) {
    Vec3 sum = Vec3::Zero();
    for (int j = off[i]; j < off[i + 1]; ++j) sum += Eigen::Map<const Vec3>(buffer + 3 * static_cast<size_t>(inc[j]));
    Eigen::Map<Vec3>(out + 3 * static_cast<size_t>(i)) = sum;
  }
}

template <int K>
void ElasticForces::SampleDecompositions(const VectorXd& x, int e0, int count, Mat3* F, Svd3* svd,
                                         VolumeProjection* volume, bool warm_start) {
  const int q_per = fem_.samples_per_element();
  const int n = count * q_per;
  DIFFPD_CHECK(n <= kSvdBatch, "more samples than an SVD batch: " << n);
  const int s0 = e0 * q_per;
  for (int j = 0; j < count; ++j) {
    const Eigen::Matrix<double, 3, K> xe = GatherElement<K>(fem_.mesh(), x, e0 + j);
    for (int q = 0; q < q_per; ++q) F[j * q_per + q] = DeformationGradient<K>(xe, fem_.grad(s0 + j * q_per + q));
  }
  if (!needs_svd_) return;
  // All samples' SVDs together, warm started from the last ones or cold.
  if (warm_start) {
    ComputeSvd3Batch(n, F, &v_cache_[s0], svd);
    for (int i = 0; i < n; ++i) v_cache_[s0 + i] = svd[i].V;
  } else {
    Mat3 cold[kSvdBatch];
    for (Mat3& v : cold) v.setIdentity();
    ComputeSvd3Batch(n, F, cold, svd);
  }
  if (!needs_volume_ || volume == nullptr) return;
  Vec3 sigma[kSvdBatch];
  for (int i = 0; i < n; ++i) sigma[i] = svd[i].sigma;
  ProjectSingularValuesToUnitDeterminantBatch(n, sigma, volume);
}

template <int K, class Body>
void ElasticForces::VisitDecomposedBatch(const VectorXd& x, int e0, int count, Body&& body, bool warm_start) {
  const int q_per = fem_.samples_per_element();
  Mat3 F[kSvdBatch];
  Svd3 svd[kSvdBatch];
  VolumeProjection volume[kSvdBatch];
  SampleDecompositions<K>(x, e0, count, F, svd, volume, warm_start);
  for (int j = 0; j < count; ++j) {
    const int i = j * q_per;
    body(e0 + j, F + i, svd + i, needs_volume_ ? volume + i : nullptr);
  }
}

template <int K, class Body>
void ElasticForces::ForEachDecomposedElement(const VectorXd& x, int threads, Body&& body, bool warm_start) {
  ParallelForSampleBatches(fem_.num_elements(), fem_.samples_per_element(), threads,
                           [&](int e0, int count) { VisitDecomposedBatch<K>(x, e0, count, body, warm_start); });
}

template <int K>
double ElasticForces::EnergyAndGradientImpl(const VectorXd& x, const LameField& lame, VectorXd* grad, int threads) {
  if (!x.allFinite()) throw SolverError(SolverStatus::kNonFinite, "positions are not finite");
  const int q_per = fem_.samples_per_element();
  // The general path for element e (F, svd, volume: its samples').
  auto element = [&](int e, const Mat3* F, const Svd3* svd, const VolumeProjection* volume) {
    const double mu = lame.mu_of(e), lambda = lame.lambda_of(e);
    Eigen::Matrix<double, 3, K> fe = Eigen::Matrix<double, 3, K>::Zero();
    double energy = 0;
    for (int q = 0; q < q_per; ++q) {
      const int s = e * q_per + q;
      const double* g = fem_.grad(s);
      Mat3 P;
      const double vol = fem_.sample_volume(s);
      energy += vol * EvaluateDensity(energies_, F[q], svd[q], mu, lambda, grad ? &P : nullptr, nullptr,
                                      volume ? &volume[q] : nullptr);
      if (grad) fe.noalias() += (vol * P) * Eigen::Map<const Eigen::Matrix<double, K, 3>>(g).transpose();
    }
    element_energy_[e] = energy;
    if (grad) Eigen::Map<Eigen::Matrix<double, 3, K>>(element_buffer_.data() + static_cast<size_t>(e) * 3 * K) = fe;
  };
  if (K == 8 && pd_hex_kernel_) {  // hexahedra (8 samples each), PD energies only: the fused kernel
    ParallelForSampleBatches(fem_.num_elements(), q_per, threads, [&](int e0, int count) {
      Eigen::Matrix<double, 3, K> xe[kPdHexBatch];
      PdHexElement batch[kPdHexBatch];
      for (int j = 0; j < count; ++j) {
        const int e = e0 + j;
        xe[j] = GatherElement<K>(fem_.mesh(), x, e);
        PdHexElement& element = batch[j];
        element.xe = xe[j].data();
        element.lane_gradients = hex_lane_gradients_.data() + static_cast<size_t>(e) * kHexLaneGradients;
        element.grads = fem_.grad(8 * e);
        element.sample_volume = fem_.sample_volumes(8 * e);
        element.weights.rotation = rotation_terms_ * 2.0 * lame.mu_of(e);
        element.weights.volume = volume_terms_ * lame.lambda_of(e);
        element.v_cache = &v_cache_[8 * static_cast<size_t>(e)];
        element.fe = element_buffer_.data() + static_cast<size_t>(e) * 3 * K;
        element.energy = &element_energy_[e];
      }
      if (!PdHexEnergyAndForces(batch, count)) VisitDecomposedBatch<K>(x, e0, count, element);
    });
  } else {
    ForEachDecomposedElement<K>(x, threads, element);
  }
  double total = 0;
  for (double v : element_energy_) total += v;
  if (!std::isfinite(total))
    throw SolverError(SolverStatus::kNonFinite, "elastic energy is not finite at the current state");
  if (grad) GatherElementBuffer(grad, threads);
  return total;
}

double ElasticForces::EnergyAndGradient(const VectorXd& x, const LameField& lame, VectorXd* grad, int threads) {
  return fem_.nodes_per_element() == 4 ? EnergyAndGradientImpl<4>(x, lame, grad, threads)
                                       : EnergyAndGradientImpl<8>(x, lame, grad, threads);
}

template <int K, class Body>
void ElasticForces::ForEachUnitLameElement(const VectorXd& x, int threads, Body&& body) {
  if (!x.allFinite()) throw SolverError(SolverStatus::kNonFinite, "positions are not finite");
  const int q_per = fem_.samples_per_element();
  ForEachDecomposedElement<K>(
      x, threads,
      [&](int e, const Mat3* F, const Svd3* svd, const VolumeProjection* volume) {
        Eigen::Matrix<double, 3, K> f_mu = Eigen::Matrix<double, 3, K>::Zero(), f_lambda = f_mu;
        for (int q = 0; q < q_per; ++q) {
          const int s = e * q_per + q;
          const double* g = fem_.grad(s);
          Mat3 p_mu, p_lambda;  // one SVD and projection serve both unit-parameter stresses
          const VolumeProjection* vq = volume ? &volume[q] : nullptr;
          EvaluateDensity(energies_, F[q], svd[q], 1.0, 0.0, &p_mu, nullptr, vq);
          EvaluateDensity(energies_, F[q], svd[q], 0.0, 1.0, &p_lambda, nullptr, vq);
          const auto gt = Eigen::Map<const Eigen::Matrix<double, K, 3>>(g).transpose();
          const double vol = fem_.sample_volume(s);
          f_mu.noalias() += (vol * p_mu) * gt;
          f_lambda.noalias() += (vol * p_lambda) * gt;
        }
        body(e, f_mu, f_lambda);
      },
      /*warm_start=*/false);
}

template <int K>
void ElasticForces::PartLameDotsImpl(const VectorXd& x, const VectorXd& z, const std::vector<int>& part_of_element,
                                     int num_parts, VectorXd* dmu, VectorXd* dlambda, int threads) {
  const Mesh& mesh = fem_.mesh();
  element_dot_.resize(fem_.num_elements());
  ForEachUnitLameElement<K>(x, threads, [&](int e, const auto& f_mu, const auto& f_lambda) {
    const Eigen::Matrix<double, 3, K> ze = GatherElement<K>(mesh, z, e);
    element_energy_[e] = ze.cwiseProduct(f_mu).sum();
    element_dot_[e] = ze.cwiseProduct(f_lambda).sum();
  });
  SumPartDots(element_energy_, element_dot_, part_of_element, num_parts, dmu, dlambda);
}

template <int K>
void ElasticForces::AddSampleUnitGradients(int s, const Mat3& F, const Svd3& svd, const VolumeProjection* volume,
                                           double* g) const {
  // One SVD and projection serve both unit-parameter stresses; pd-corotated
  // (2 mu) has none at (0, 1), pd-volume (lambda) none at (1, 0).
  Mat3 p_mu = Mat3::Zero(), p_lambda = Mat3::Zero(), p;
  for (const ElasticEnergy energy : energies_) {
    if (energy != ElasticEnergy::kPdVolume) {
      EnergyAndStress(energy, F, svd, 1.0, 0.0, &p, volume);
      p_mu += p;
    }
    if (energy != ElasticEnergy::kPdCorotated) {
      EnergyAndStress(energy, F, svd, 0.0, 1.0, &p, volume);
      p_lambda += p;
    }
  }
  const auto gt = Eigen::Map<const Eigen::Matrix<double, K, 3>>(fem_.grad(s)).transpose();
  const double vol = fem_.sample_volume(s);
  Eigen::Map<Eigen::Matrix<double, 3, K>>(g).noalias() += (vol * p_mu) * gt;
  Eigen::Map<Eigen::Matrix<double, 3, K>>(g + 3 * K).noalias() += (vol * p_lambda) * gt;
}

void ElasticForces::LameDotsFromUnitGradients(const std::vector<double>& unit_gradients, const VectorXd& z,
                                              const std::vector<int>& part_of_element, int num_parts, VectorXd* dmu,
                                              VectorXd* dlambda) const {
  const int m = fem_.num_elements();
  DIFFPD_CHECK(unit_gradients.size() == static_cast<size_t>(6 * fem_.nodes_per_element()) * m,
               "LameDotsFromUnitGradients: " << unit_gradients.size() << " entries for " << m << " elements");
  DIFFPD_CHECK(part_of_element.empty() || static_cast<int>(part_of_element.size()) == m,
               "part_of_element has " << part_of_element.size() << " entries");
  std::vector<double> dots_mu(m), dots_lambda(m);
  if (fem_.nodes_per_element() == 4)
    UnitGradientDots<4>(unit_gradients, z, &dots_mu, &dots_lambda);
  else
    UnitGradientDots<8>(unit_gradients, z, &dots_mu, &dots_lambda);
  SumPartDots(dots_mu, dots_lambda, part_of_element, num_parts, dmu, dlambda);
}

template <int K>
void ElasticForces::UnitGradientDots(const std::vector<double>& unit_gradients, const VectorXd& z,
                                     std::vector<double>* dots_mu, std::vector<double>* dots_lambda) const {
  const Mesh& mesh = fem_.mesh();
  using Block = Eigen::Matrix<double, 3, K>;
  for (int e = 0; e < fem_.num_elements(); ++e) {
    const double* g = unit_gradients.data() + static_cast<size_t>(6 * K) * e;
    // PartLameDots' expressions, so that equal gradients give equal dots.
    const Block ze = GatherElement<K>(mesh, z, e);
    const Block f_mu = Eigen::Map<const Block>(g), f_lambda = Eigen::Map<const Block>(g + 3 * K);
    (*dots_mu)[e] = ze.cwiseProduct(f_mu).sum();
    (*dots_lambda)[e] = ze.cwiseProduct(f_lambda).sum();
  }
}

template <int K>
void ElasticForces::LameDirectionGradientImpl(const VectorXd& x, const LameField& direction, VectorXd* grad,
                                              int threads) {
  ForEachUnitLameElement<K>(x, threads, [&](int e, const auto& f_mu, const auto& f_lambda) {
    Eigen::Map<Eigen::Matrix<double, 3, K>>(element_buffer_.data() + static_cast<size_t>(e) * 3 * K) =
        direction.mu_of(e) * f_mu + direction.lambda_of(e) * f_lambda;
  });
  GatherElementBuffer(grad, threads);
  if (!grad->allFinite())
    throw SolverError(SolverStatus::kNonFinite, "the elastic gradient along the Lame direction is not finite");
}

void ElasticForces::LameDirectionGradient(const VectorXd& x, const LameField& direction, VectorXd* grad, int threads) {
  if (fem_.nodes_per_element() == 4)
    LameDirectionGradientImpl<4>(x, direction, grad, threads);
  else
    LameDirectionGradientImpl<8>(x, direction, grad, threads);
}

void ElasticForces::PartLameDots(const VectorXd& x, const VectorXd& z, const std::vector<int>& part_of_element,
                                 int num_parts, VectorXd* dmu, VectorXd* dlambda, int threads) {
  DIFFPD_CHECK(part_of_element.empty() || static_cast<int>(part_of_element.size()) == fem_.num_elements(),
               "part_of_element has " << part_of_element.size() << " entries");
  if (fem_.nodes_per_element() == 4)
    PartLameDotsImpl<4>(x, z, part_of_element, num_parts, dmu, dlambda, threads);
  else
    PartLameDotsImpl<8>(x, z, part_of_element, num_parts, dmu, dlambda, threads);
}

template <int K>
void ElasticForces::StressDifferentialsImpl(const VectorXd& x, const LameField& lame, std::vector<Mat9>* d,
                                            int threads) {
  const Mesh& mesh = fem_.mesh();
  const int q_per = fem_.samples_per_element();
  d->resize(fem_.num_samples());
  ParallelForElements(fem_.num_elements(), threads, [&](int e) {
    const double mu = lame.mu_of(e), lambda = lame.lambda_of(e);
    const Eigen::Matrix<double, 3, K> xe = GatherElement<K>(mesh, x, e);
    for (int q = 0; q < q_per; ++q) {
      const int s = e * q_per + q;
      const Mat3 F = DeformationGradient<K>(xe, fem_.grad(s));
      EvaluateDensity(energies_, F, mu, lambda, nullptr, &(*d)[s]);
      (*d)[s] *= fem_.sample_volume(s);
    }
  });
}

void ElasticForces::StressDifferentials(const VectorXd& x, const LameField& lame, std::vector<Mat9>* d, int threads) {
  if (fem_.nodes_per_element() == 4)
    StressDifferentialsImpl<4>(x, lame, d, threads);
  else
    StressDifferentialsImpl<8>(x, lame, d, threads);
}

template <int K>
void ElasticForces::ApplyHessianImpl(const std::vector<Mat9>& d, const VectorXd& z, VectorXd* out, int threads) {
  const Mesh& mesh = fem_.mesh();
  const int q_per = fem_.samples_per_element();
  ParallelForElements(fem_.num_elements(), threads, [&](int e) {
    const Eigen::Matrix<double, 3, K> ze = GatherElement<K>(mesh, z, e);
    Eigen::Matrix<double, 3, K> fe = Eigen::Matrix<double, 3, K>::Zero();
    for (int q = 0; q < q_per; ++q) {
      const int s = e * q_per + q;
      const Eigen::Map<const Eigen::Matrix<double, K, 3>> g(fem_.grad(s));
      const Mat3 dF = ze * g;
      const Vec9 dp = d[s].lazyProduct(Eigen::Map<const Vec9>(dF.data()));  // volume already folded into d
      fe.noalias() += Eigen::Map<const Mat3>(dp.data()) * g.transpose();
    }
    Eigen::Map<Eigen::Matrix<double, 3, K>>(element_buffer_.data() + static_cast<size_t>(e) * 3 * K) = fe;
  });
  GatherElementBuffer(out, threads);
}

void ElasticForces::ApplyHessian(const std::vector<Mat9>& d, const VectorXd& z, VectorXd* out, int threads) {
  if (fem_.nodes_per_element() == 4)
    ApplyHessianImpl<4>(d, z, out, threads);
  else
    ApplyHessianImpl<8>(d, z, out, threads);
}

namespace {

// Writes element e's upper 3 x 3 node blocks of ke (3k x 3k, column-major)
// into its lane of the packed layout (packed_element_matrices.h).
void PackElement(int k, int e, const double* ke, double* packed) {
  const int n = 3 * k;
  double* out = packed + static_cast<size_t>(e / kElementLanes) * PackedEntries(k) * kElementLanes + e % kElementLanes;
  for (int b = 0; b < k; ++b)
    for (int a = 0; a <= b; ++a)
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r, out += kElementLanes) *out = ke[(3 * b + c) * n + 3 * a + r];
}

}  // namespace

void ElasticForces::PackElementMatrices(const std::vector<double>& blocks, std::vector<double>* packed) const {
  const int k = fem_.nodes_per_element(), n = 3 * k, m = fem_.num_elements();
  DIFFPD_CHECK(blocks.size() == static_cast<size_t>(m) * n * n,
               "PackElementMatrices: " << blocks.size() << " block entries for " << m << " elements");
  const int groups = (m + kElementLanes - 1) / kElementLanes;
  packed->assign(static_cast<size_t>(groups) * PackedEntries(k) * kElementLanes, 0.0);
  for (int e = 0; e < m; ++e) PackElement(k, e, blocks.data() + static_cast<size_t>(e) * n * n, packed->data());
}

template <int K>
void ElasticForces::PackedElementHessiansImpl(const VectorXd& x, const LameField& lame, std::vector<double>* packed,
                                              int threads, std::vector<double>* unit_gradients, bool warm_start) {
  constexpr int N = 3 * K;
  const int q_per = fem_.samples_per_element(), m = fem_.num_elements();
  const int groups = (m + kElementLanes - 1) / kElementLanes;
  const size_t group_entries = static_cast<size_t>(PackedEntries(K)) * kElementLanes;
  // Cleared here, or group by group in the lane-by-lane pass (while in cache).
  if (coefficient_form_)
    packed->resize(groups * group_entries);
  else
    packed->assign(groups * group_entries, 0.0);
  if (unit_gradients) unit_gradients->assign(static_cast<size_t>(6 * K) * m, 0.0);
  // Element e's unit-parameter gradients from its samples (i: e's first).
  const auto add_unit_gradients = [&](int e, const Mat3* F, const Svd3* svd, const VolumeProjection* volume) {
    double* g = unit_gradients->data() + static_cast<size_t>(6 * K) * e;
    for (int q = 0; q < q_per; ++q)
      AddSampleUnitGradients<K>(e * q_per + q, F[q], svd[q], needs_volume_ ? &volume[q] : nullptr, g);
  };
  if (coefficient_form_) {
    DIFFPD_CHECK(q_per <= kMaxSamplesPerElement, "PackedElementHessians: " << q_per << " samples per element");
    // Lane by lane over each group's elements, one sample index at a time:
    // the decompositions in SVD batches, the differential coefficients per
    // sample, then AddPackedSampleStiffness.
    const int per_batch = std::max(1, kSvdBatch / q_per);
    ParallelForElements(
        groups, threads,
        [&](int g) {
          const int e0 = g * kElementLanes, count = std::min(kElementLanes, m - e0);
          Mat3 F[kElementLanes * kMaxSamplesPerElement];
          Svd3 svd[kElementLanes * kMaxSamplesPerElement];
          VolumeProjection volume[kElementLanes * kMaxSamplesPerElement];
          for (int j = 0; j < count; j += per_batch)
            SampleDecompositions<K>(x, e0 + j, std::min(per_batch, count - j), F + j * q_per, svd + j * q_per,
                                    volume + j * q_per, warm_start);
          if (unit_gradients)
            for (int j = 0; j < count; ++j)
              add_unit_gradients(e0 + j, F + j * q_per, svd + j * q_per, volume + j * q_per);
          PackedSampleLanes lanes{};  // lanes without an element stay zero
          double* out = packed->data() + g * group_entries;
          std::fill(out, out + group_entries, 0.0);
          for (int q = 0; q < q_per; ++q) {
            for (int j = 0; j < count; ++j) {
              const int e = e0 + j, i = j * q_per + q, sample = e * q_per + q;
              IsotropicDifferentialCoefficients sum;
              for (const ElasticEnergy energy : energies_)
                sum += StressDifferentialCoefficients(energy, svd[i], lame.mu_of(e), lame.lambda_of(e),
                                                      needs_volume_ ? &volume[i] : nullptr);
              for (int k = 0; k < 9; ++k) {
                lanes.u[k][j] = svd[i].U(k);
                lanes.v[k][j] = svd[i].V(k);
                lanes.dp_dsigma[k][j] = sum.dp_dsigma(k);
              }
              for (int k = 0; k < 3; ++k) {
                lanes.symmetric[k][j] = sum.symmetric(k);
                lanes.skew[k][j] = sum.skew(k);
              }
              lanes.volume[j] = fem_.sample_volume(sample);
              const double* grad = fem_.grad(sample);
              for (int k = 0; k < 3 * K; ++k) lanes.grad[k][j] = grad[k];
            }
            AddPackedSampleStiffness(K, lanes, out);
          }
        },
        std::max(1, kMinParallelElements / kElementLanes));
    return;
  }
  ParallelForSampleBatches(m, q_per, threads, [&](int e0, int count) {
    Mat3 F[kSvdBatch];
    Svd3 svd[kSvdBatch];
    VolumeProjection volume[kSvdBatch];
    SampleDecompositions<K>(x, e0, count, F, svd, volume, warm_start);
    Eigen::Matrix<double, N, N> ke;
    for (int j = 0; j < count; ++j) {
      ElementStiffness<K, /*kUpper=*/true>(e0 + j, F + j * q_per, svd + j * q_per, volume + j * q_per, lame, ke.data());
      PackElement(K, e0 + j, ke.data(), packed->data());
      if (unit_gradients) add_unit_gradients(e0 + j, F + j * q_per, svd + j * q_per, volume + j * q_per);
    }
  });
}

void ElasticForces::PackedElementHessians(const VectorXd& x, const LameField& lame, std::vector<double>* packed,
                                          int threads, std::vector<double>* unit_gradients, bool warm_start) {
  if (!x.allFinite()) throw SolverError(SolverStatus::kNonFinite, "positions are not finite");
  if (fem_.nodes_per_element() == 4)
    PackedElementHessiansImpl<4>(x, lame, packed, threads, unit_gradients, warm_start);
  else
    PackedElementHessiansImpl<8>(x, lame, packed, threads, unit_gradients, warm_start);
}

template <int K>
void ElasticForces::ApplyElementMatricesImpl(const std::vector<double>& packed, const Eigen::Ref<const MatrixXd>& z,
                                             double* out, int threads) {
  const size_t entries = PackedEntries(K);
  const Mesh& mesh = fem_.mesh();
  const int m = fem_.num_elements(), cols = static_cast<int>(z.cols());
  const int groups = (m + kElementLanes - 1) / kElementLanes;
  DIFFPD_CHECK(packed.size() == static_cast<size_t>(groups) * entries * kElementLanes,
               "ApplyElementMatrices: " << packed.size() << " packed entries for " << m << " elements");
  // One element buffer per column (the single-column product uses
  // element_buffer_ itself).
  const size_t buffer_size = static_cast<size_t>(m) * 3 * K;
  double* buffer = element_buffer_.data();
  if (cols > 1) {
    if (column_buffer_.size() < buffer_size * cols) column_buffer_.resize(buffer_size * cols);
    buffer = column_buffer_.data();
  }
  ParallelForElements(
      groups, threads,
      [&](int g) {
        alignas(64) double zl[3 * K][kElementLanes];
        alignas(64) double yl[3 * K][kElementLanes];
        const int count = std::min(kElementLanes, m - g * kElementLanes);
        const double* group = packed.data() + static_cast<size_t>(g) * entries * kElementLanes;
        for (int c = 0; c < cols; ++c) {
          for (int j = 0; j < kElementLanes; ++j) {
            const int e = g * kElementLanes + j;
            for (int a = 0; a < K; ++a) {
              const int node = j < count ? mesh.elements(a, e) : 0;
              for (int i = 0; i < 3; ++i) zl[3 * a + i][j] = j < count ? z(3 * node + i, c) : 0.0;
            }
          }
          ApplyPackedGroup(K, group, zl, yl);
          for (int j = 0; j < count; ++j) {
            double* ye = buffer + buffer_size * c + static_cast<size_t>(g * kElementLanes + j) * 3 * K;
            for (int r = 0; r < 3 * K; ++r) ye[r] = yl[r][j];
          }
        }
      },
      std::max(1, kMinParallelElements / kElementLanes));
  for (int c = 0; c < cols; ++c)
    GatherBuffer(buffer + buffer_size * c, out + static_cast<size_t>(z.rows()) * c, threads);
}

void ElasticForces::ApplyElementMatrices(const std::vector<double>& packed, const VectorXd& z, VectorXd* out,
                                         int threads) {
  out->resize(z.size());
  if (fem_.nodes_per_element() == 4)
    ApplyElementMatricesImpl<4>(packed, z, out->data(), threads);
  else
    ApplyElementMatricesImpl<8>(packed, z, out->data(), threads);
}

void ElasticForces::ApplyElementMatricesToColumns(const std::vector<double>& packed, const MatrixXd& z, MatrixXd* out,
                                                  int threads) {
  DIFFPD_CHECK(z.rows() == 3 * fem_.num_nodes(),
               "ApplyElementMatricesToColumns: " << z.rows() << " rows for " << fem_.num_nodes() << " nodes");
  out->resize(z.rows(), z.cols());
  if (z.cols() == 0) return;
  if (fem_.nodes_per_element() == 4)
    ApplyElementMatricesImpl<4>(packed, z, out->data(), threads);
  else
    ApplyElementMatricesImpl<8>(packed, z, out->data(), threads);
}

template <int K, bool kUpper>
void ElasticForces::ElementStiffness(int e, const Mat3* F, const Svd3* svd, const VolumeProjection* volume,
                                     const LameField& lame, double* block) const {
  constexpr int N = 3 * K;
  const int q_per = fem_.samples_per_element();
  const double mu = lame.mu_of(e), lambda = lame.lambda_of(e);
  Eigen::Map<Eigen::Matrix<double, N, N>> ke(block);
  ke.setZero();
  for (int q = 0; q < q_per; ++q) {
    Mat9 dP;
    EvaluateDensity(energies_, F[q], svd[q], mu, lambda, nullptr, &dP, needs_volume_ ? &volume[q] : nullptr);
    AddSampleStiffness<K, kUpper>(fem_.grad(e * q_per + q), fem_.sample_volume(e * q_per + q), dP, ke);
  }
}

template <int K>
void ElasticForces::ElementHessiansImpl(const VectorXd& x, const LameField& lame, bool project_spd,
                                        std::vector<double>* blocks, int threads) {
  constexpr int N = 3 * K;
  const int q_per = fem_.samples_per_element();
  blocks->resize(static_cast<size_t>(fem_.num_elements()) * N * N);
  // SVDs in batches, cold started (identity guesses): the blocks depend on x
  // alone, not on what was evaluated before.
  ParallelForSampleBatches(fem_.num_elements(), q_per, threads, [&](int e0, int count) {
    Mat3 F[kSvdBatch];
    Svd3 svd[kSvdBatch];
    VolumeProjection volume[kSvdBatch];
    SampleDecompositions<K>(x, e0, count, F, svd, volume, /*warm_start=*/false);
    for (int j = 0; j < count; ++j) {
      const int e = e0 + j;
      double* block = blocks->data() + static_cast<size_t>(e) * N * N;
      ElementStiffness<K>(e, F + j * q_per, svd + j * q_per, volume + j * q_per, lame, block);
      if (project_spd) {
        Eigen::Map<Eigen::Matrix<double, N, N>> ke(block);
        const Eigen::Matrix<double, N, N> sym = 0.5 * (ke + ke.transpose());
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(sym);
        if (eig.eigenvalues().minCoeff() < 0) {
          const Eigen::Matrix<double, N, 1> lam = eig.eigenvalues().cwiseMax(0.0);
          ke = eig.eigenvectors() * lam.asDiagonal() * eig.eigenvectors().transpose();
        }
      }
    }
  });
}

template <int K>
void ElasticForces::AddElementHessianProductsImpl(const VectorXd& x, const LameField& lame,
                                                  const std::vector<int>& elements, const MatrixXd& z, MatrixXd* out) {
  constexpr int N = 3 * K;
  const Mesh& mesh = fem_.mesh();
  Mat3 F[kSvdBatch];
  Svd3 svd[kSvdBatch];
  VolumeProjection volume[kSvdBatch];
  Eigen::Matrix<double, N, N> ke;
  Eigen::Matrix<double, N, Eigen::Dynamic> ze(N, z.cols());
  for (const int e : elements) {
    DIFFPD_CHECK(e >= 0 && e < fem_.num_elements(), "AddElementHessianProducts: element " << e);
    SampleDecompositions<K>(x, e, 1, F, svd, volume, /*warm_start=*/false);
    ElementStiffness<K>(e, F, svd, volume, lame, ke.data());
    for (int a = 0; a < K; ++a) ze.template middleRows<3>(3 * a) = z.middleRows<3>(3 * mesh.elements(a, e));
    const Eigen::Matrix<double, N, Eigen::Dynamic> ye = ke * ze;
    for (int a = 0; a < K; ++a) out->middleRows<3>(3 * mesh.elements(a, e)) += ye.template middleRows<3>(3 * a);
  }
}

void ElasticForces::AddElementHessianProducts(const VectorXd& x, const LameField& lame,
                                              const std::vector<int>& elements, const MatrixXd& z, MatrixXd* out) {
  DIFFPD_CHECK(
      z.rows() == x.size() && out->rows() == x.size() && out->cols() == z.cols(),
      "AddElementHessianProducts: shapes " << z.rows() << "x" << z.cols() << ", " << out->rows() << "x" << out->cols());
  if (fem_.nodes_per_element() == 4)
    AddElementHessianProductsImpl<4>(x, lame, elements, z, out);
  else
    AddElementHessianProductsImpl<8>(x, lame, elements, z, out);
}

void ElasticForces::ElementHessians(const VectorXd& x, const LameField& lame, bool project_spd,
                                    std::vector<double>* blocks, int threads) {
  if (fem_.nodes_per_element() == 4)
    ElementHessiansImpl<4>(x, lame, project_spd, blocks, threads);
  else
    ElementHessiansImpl<8>(x, lame, project_spd, blocks, threads);
}

}  // namespace diffpd::internal
