// Elastic energy of a discretised body and its derivatives (internal).
//
// E(x) = sum_s vol_s * sum_{energies} Psi(F_s(x); mu_e, lambda_e), with F_s
// the deformation gradient at sample s (see fem_model.h) and (mu_e, lambda_e)
// the Lame parameters of its element e (a LameField: uniform or per element).
// Every density is linear in the Lame parameters, so d grad E / d mu is grad E
// evaluated with (mu, lambda) = (1, 0), and the derivative along a field of
// Lame directions (dmu_e, dlambda_e) is grad E evaluated with that field.
// All loops run over elements in parallel (OpenMP, `threads` threads, 0 means
// the OpenMP default); results are gathered per node, so they are
// deterministic for a given thread count.
#pragma once

#include <vector>

#include "diffpd/material.h"
#include "diffpd/types.h"
#include "fem/fem_model.h"
#include "fem/lame_field.h"
#include "material/projections.h"
#include "material/svd3.h"

namespace diffpd::internal {

class ElasticForces {
 public:
  // Does not take ownership of `fem`, which must outlive this object.
  ElasticForces(const FemModel& fem, std::vector<ElasticEnergy> energies);

  const std::vector<ElasticEnergy>& energies() const { return energies_; }
  bool all_projective() const { return all_projective_; }

  // Weight of the constant PD matrix: sum over energies of w (2 mu for
  // pd-corotated, lambda for pd-volume; 2 mu + lambda for energies that are
  // not of PD form, used only as the quasi-Newton initial Hessian).
  double PdWeight(double mu, double lambda) const;

  // Resets the SVDs' warm start (every sample's V) to the identity, so that
  // what follows depends on its inputs alone, not on earlier evaluations.
  // Every step calls it first when SolverOptions::svd_warm_start is false: a
  // step is then a function of its state and input, recomputed bit for bit
  // (checkpointed_rollout.h).
  void ResetWarmStart();

  // Returns E(x) (J) and, if grad != nullptr, sets *grad = dE/dx (3n, N).
  // Throws SolverError(kInvertedElement) for neo-Hookean with det F <= 0 and
  // SolverError(kNonFinite) when x produces a non-finite value.
  double EnergyAndGradient(const VectorXd& x, const LameField& lame, VectorXd* grad, int threads);

  // For every part p of the elements (part_of_element: num_elements entries
  // in [0, num_parts), or empty: all in part 0), the derivatives of z . grad E(x)
  // w.r.t. the part's Lame parameters (one pass over the elements):
  //   (*dmu)(p)     = sum_{e in p} z_e . d(grad_e E)/d mu_e,
  //   (*dlambda)(p) = sum_{e in p} z_e . d(grad_e E)/d lambda_e.
  // Per-element values are summed in element order: deterministic.
  void PartLameDots(const VectorXd& x, const VectorXd& z, const std::vector<int>& part_of_element, int num_parts,
                    VectorXd* dmu, VectorXd* dlambda, int threads);
  // *grad = d(grad E)/d(mu, lambda) along a field of Lame directions
  // (dmu_e, dlambda_e) = (direction.mu_of(e), direction.lambda_of(e)) at x:
  //   sum_e dmu_e d(grad_e E)/d mu_e + dlambda_e d(grad_e E)/d lambda_e (3n, N/Pa).
  // PartLameDots and this evaluate the same unit-parameter element forces
  // bit for bit (cold-started SVDs: a function of x alone), so a reverse pass
  // built on the one and a forward-mode pass built on the other transpose
  // each other exactly. Where a volumetric strain sits near the rounding of
  // F (stiff, nearly incompressible material: strain ~ stress / lambda), two
  // evaluations of the pd-volume stress that round differently differ far
  // above machine precision (see docs/benchmarks.md, "Gradient checks with a
  // verdict"), which is why neither pass may evaluate it its own way.
  void LameDirectionGradient(const VectorXd& x, const LameField& direction, VectorXd* grad, int threads);

  // Per-sample exact stress differentials dP/dF (summed over energies) at x.
  void StressDifferentials(const VectorXd& x, const LameField& lame, std::vector<Mat9>* d, int threads);
  // out = (d^2 E / dx^2) z using stress differentials from StressDifferentials.
  void ApplyHessian(const std::vector<Mat9>& d, const VectorXd& z, VectorXd* out, int threads);

  // Element Hessians (3K x 3K each, column-major, concatenated; row and
  // column 3a + i: node a of the element, axis i) at x; with project_spd each
  // is replaced by its projection onto the PSD cone (negative eigenvalues
  // clamped to zero), the definiteness fix of Newton. Depends on x only (the
  // SVDs are cold started).
  void ElementHessians(const VectorXd& x, const LameField& lame, bool project_spd, std::vector<double>* blocks,
                       int threads);
  // out += sum over the listed elements of K_e z_e for each column of z
  // (3n x P): the element Hessians at x (not projected), computed for those
  // elements only (serial; for a few elements, e.g. those around fixed nodes).
  void AddElementHessianProducts(const VectorXd& x, const LameField& lame, const std::vector<int>& elements,
                                 const MatrixXd& z, MatrixXd* out);
  // The upper triangle of each (symmetric) element block by 3 x 3 node
  // blocks, interleaved across groups of elements (layout in
  // packed_element_matrices.h; 1296 of 2304 bytes per hexahedron).
  void PackElementMatrices(const std::vector<double>& blocks, std::vector<double>* packed) const;
  // The same packed matrices straight from x (ElementHessians, unprojected,
  // then PackElementMatrices, equal to rounding), in parallel, without the
  // full blocks: 8 elements per vector operation when every energy is
  // SVD-coefficient based (AddPackedSampleStiffness), else element by
  // element (bit for bit). With `unit_gradients` != nullptr the same pass
  // (the same SVDs) also fills it with every element's unit-parameter
  // gradients, the input of LameDotsFromUnitGradients: per element e,
  // 6K doubles, d(grad_e E)/d mu_e (3 x K, column-major) then
  // d(grad_e E)/d lambda_e. With warm_start the SVDs start from, and update,
  // the warm-start cache as EnergyAndGradient's do (equal to rounding; after
  // ResetWarmStart exactly the cold ones); without it (the backward pass)
  // they start cold, as PartLameDots' do, and the result depends on x alone.
  void PackedElementHessians(const VectorXd& x, const LameField& lame, std::vector<double>* packed, int threads,
                             std::vector<double>* unit_gradients = nullptr, bool warm_start = false);
  // PartLameDots(x, z, ...) from the unit gradients at x that
  // PackedElementHessians made (num_elements * 6K entries): the same dots,
  // summed in the same order, without evaluating the material again (bit
  // for bit PartLameDots' when the gradients came from cold SVDs). Throws SolverError(kNonFinite) like PartLameDots.
  void LameDotsFromUnitGradients(const std::vector<double>& unit_gradients, const VectorXd& z,
                                 const std::vector<int>& part_of_element, int num_parts, VectorXd* dmu,
                                 VectorXd* dlambda) const;
  // out = sum_e K_e z_e with packed element Hessians: the Hessian product for
  // many products at one x ((3K)^2 multiply-adds per element and product,
  // against about 3 (3K)^2 through StressDifferentials for hexahedra, and
  // half the memory traffic of full blocks).
  void ApplyElementMatrices(const std::vector<double>& packed, const VectorXd& z, VectorXd* out, int threads);
  // The same product for every column of z (3n x P) in one pass over the
  // packed matrices, each group of elements applied to all P columns while
  // its matrices are in cache: column c of *out is
  // ApplyElementMatrices(packed, z.col(c)) bit for bit, for the cost of
  // reading the matrices once.
  void ApplyElementMatricesToColumns(const std::vector<double>& packed, const MatrixXd& z, MatrixXd* out, int threads);

 private:
  template <int K>
  double EnergyAndGradientImpl(const VectorXd& x, const LameField& lame, VectorXd* grad, int threads);
  // Runs body(e, f_mu, f_lambda) for every element e (in parallel over SVD
  // batches): f_mu and f_lambda are e's 3 x K gradients d(grad_e E)/d mu_e
  // and d(grad_e E)/d lambda_e at x, from cold-started SVDs.
  template <int K, class Body>
  void ForEachUnitLameElement(const VectorXd& x, int threads, Body&& body);
  template <int K>
  void LameDirectionGradientImpl(const VectorXd& x, const LameField& direction, VectorXd* grad, int threads);
  template <int K>
  void PartLameDotsImpl(const VectorXd& x, const VectorXd& z, const std::vector<int>& part_of_element, int num_parts,
                        VectorXd* dmu, VectorXd* dlambda, int threads);
  template <int K>
  void StressDifferentialsImpl(const VectorXd& x, const LameField& lame, std::vector<Mat9>* d, int threads);
  template <int K>
  void ApplyHessianImpl(const std::vector<Mat9>& d, const VectorXd& z, VectorXd* out, int threads);
  template <int K>
  void ApplyElementMatricesImpl(const std::vector<double>& packed, const Eigen::Ref<const MatrixXd>& z, double* out,
                                int threads);
  // Element e's Hessian (3K x 3K, column-major) from its samples' F, SVD
  // and volume projection (e's samples_per_element() entries each); with
  // kUpper only its upper node blocks (the rest left zero).
  template <int K, bool kUpper = false>
  void ElementStiffness(int e, const Mat3* F, const Svd3* svd, const VolumeProjection* volume, const LameField& lame,
                        double* block) const;
  template <int K>
  void AddElementHessianProductsImpl(const VectorXd& x, const LameField& lame, const std::vector<int>& elements,
                                     const MatrixXd& z, MatrixXd* out);
  template <int K>
  void PackedElementHessiansImpl(const VectorXd& x, const LameField& lame, std::vector<double>* packed, int threads,
                                 std::vector<double>* unit_gradients, bool warm_start);
  // Adds sample s's unit-parameter gradients (vol G^T-weighted stresses at
  // (mu, lambda) = (1, 0) and (0, 1)) to g (6K doubles: mu then lambda).
  template <int K>
  void UnitGradientDots(const std::vector<double>& unit_gradients, const VectorXd& z, std::vector<double>* dots_mu,
                        std::vector<double>* dots_lambda) const;
  template <int K>
  void AddSampleUnitGradients(int s, const Mat3& F, const Svd3& svd, const VolumeProjection* volume, double* g) const;
  template <int K>
  void ElementHessiansImpl(const VectorXd& x, const LameField& lame, bool project_spd, std::vector<double>* blocks,
                           int threads);
  // Deformation gradients F[i] of the samples of elements e0 .. e0+count-1
  // at positions x (count * samples_per_element <= kSvdBatch, in sample
  // order) and, when an energy needs them, their SVDs (svd[i]), computed as
  // one batch, warm started from and written back to v_cache_ (warm_start)
  // or from the identity (results depending on x alone), and (pd-volume
  // declared and volume != nullptr) the volume projections of their singular
  // values, also as one batch.
  template <int K>
  void SampleDecompositions(const VectorXd& x, int e0, int count, Mat3* F, Svd3* svd, VolumeProjection* volume,
                            bool warm_start = true);
  // Runs body(e, F, svd, volume) for elements e0 .. e0+count-1 of one SVD
  // batch (SampleDecompositions, warm started unless warm_start is false):
  // F, svd and volume point at e's samples_per_element() entries (volume is
  // nullptr unless pd-volume is declared).
  template <int K, class Body>
  void VisitDecomposedBatch(const VectorXd& x, int e0, int count, Body&& body, bool warm_start = true);
  // VisitDecomposedBatch over every element, in parallel over batches.
  template <int K, class Body>
  void ForEachDecomposedElement(const VectorXd& x, int threads, Body&& body, bool warm_start = true);
  // Sums the per-element 3 x K buffer into a 3n vector, in parallel over nodes.
  void GatherElementBuffer(VectorXd* out, int threads) const;
  // The same for a buffer laid out like element_buffer_ (3K per element),
  // into out (3n doubles).
  void GatherBuffer(const double* buffer, double* out, int threads) const;

  const FemModel& fem_;
  std::vector<ElasticEnergy> energies_;
  bool all_projective_ = true;
  bool needs_svd_ = false;
  bool needs_volume_ = false;  // pd-volume declared (volume_terms_ > 0)
  // Every energy's stress differential is isotropic-coefficient based
  // (NeedsSvd): PackedElementHessians runs lane by lane (AddPackedSampleStiffness).
  bool coefficient_form_ = false;
  std::vector<double> element_buffer_;  // 3 * K per element
  std::vector<double> column_buffer_;   // P element buffers (ApplyElementMatricesToColumns)
  std::vector<double> element_energy_;  // per element
  std::vector<double> element_dot_;     // per element (PartLameDots' lambda dots)
  // Per-sample V of the last SVD: warm start of the next one (see svd3.h).
  std::vector<Mat3> v_cache_;
  // Hexahedra with PD energies only: the fused kernel (pd_hex_kernel.h), its
  // lane-ordered shape gradients (kHexLaneGradients per element) and the
  // number of pd-corotated / pd-volume terms declared.
  bool pd_hex_kernel_ = false;
  std::vector<double> hex_lane_gradients_;
  int rotation_terms_ = 0, volume_terms_ = 0;
};

// Energy density, stress and (optionally) stress differential of the sum of
// `energies` at F, with one SVD shared by the energies that need it (warm
// started from and written back to *v_cache when given). Throws SolverError
// for inverted neo-Hookean elements.
double EvaluateDensity(const std::vector<ElasticEnergy>& energies, const Mat3& F, double mu, double lambda,
                       Mat3* stress, Mat9* dstress, Mat3* v_cache = nullptr);
// The same with the signed SVD of F given (ignored when no energy needs it).
// `volume`, when given, is the pd-volume projection of svd.sigma precomputed.
double EvaluateDensity(const std::vector<ElasticEnergy>& energies, const Mat3& F, const Svd3& svd, double mu,
                       double lambda, Mat3* stress, Mat9* dstress, const VolumeProjection* volume = nullptr);
// True when one of `energies` needs the SVD of F.
bool AnyNeedsSvd(const std::vector<ElasticEnergy>& energies);

}  // namespace diffpd::internal
