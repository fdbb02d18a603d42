#include "solver/pd_system.h"

#include <algorithm>
#include <chrono>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

// The PD factor is computed once and solved with at every iteration, by a
// blocked copy in parallel over subtrees (CholmodSolveKernel::kParallelCopy).
// The copy of the simplicial layout has no explicit zeros, the supernodal
// one has CHOLMOD's relaxed supernodes: with the simplicial one the cantilever
// (2 673 nodes, 25 steps, 2 threads) ran 5% faster in alternating runs, at
// the cost of a slower factorisation, once (26 vs 21 ms; at 18 785 nodes
// 0.70 vs 0.36 s). CHOLMOD's own solves were also faster from the simplicial
// layout (bench --scaling, 2 threads: forward 5-16% and backward 14-25% per
// run from 2 673 to 18 785 nodes). Above 20 000 nodes the supernodal layout
// is kept (measured up to 140 481 nodes). Its ordering is nested dissection,
// whatever the size (fewer factor entries than CHOLMOD's automatic choice:
// solver/cholmod_solver.h).
constexpr int kSimplicialMaxNodes = 20000;
CholmodLayout PdFactorLayout(int num_nodes) {
  return num_nodes <= kSimplicialMaxNodes ? CholmodLayout::kSimplicial : CholmodLayout::kSupernodal;
}

}  // namespace

namespace {

// sum_{e : keep(e)} L_e in the pattern of the whole mesh's Laplacian (the
// other elements' entries present as explicit zeros).
template <class Keep>
SparseMatrix Laplacian(const FemModel& fem, Keep keep) {
  const int n = fem.num_nodes();
  const int k = fem.nodes_per_element();
  const Mesh& mesh = fem.mesh();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(fem.num_elements()) * k * k);
  for (int e = 0; e < fem.num_elements(); ++e) {
    Eigen::MatrixXd le = Eigen::MatrixXd::Zero(k, k);
    if (keep(e)) {
      for (int q = 0; q < fem.samples_per_element(); ++q) {
        const int s = e * fem.samples_per_element() + q;
        const Eigen::Map<const Eigen::MatrixXd> g(fem.grad(s), k, 3);
        le.noalias() += fem.sample_volume(s) * g * g.transpose();
      }
    }
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) triplets.emplace_back(mesh.elements(a, e), mesh.elements(b, e), le(a, b));
  }
  SparseMatrix l(n, n);
  l.setFromTriplets(triplets.begin(), triplets.end());
  l.makeCompressed();
  return l;
}

bool AllEqual(const std::vector<double>& v) {
  for (const double x : v)
    if (x != v[0]) return false;
  return true;
}

}  // namespace

PdSystem::PdSystem(const FemModel& fem, const std::vector<char>& fixed, const std::vector<int>& part_of_element,
                   int num_parts)
    : fem_(fem), num_parts_(num_parts) {
  const int n = fem.num_nodes();
  DIFFPD_CHECK(num_parts >= 1 && (num_parts == 1 || static_cast<int>(part_of_element.size()) == fem.num_elements()),
               num_parts << " parts need one part per element (got " << part_of_element.size() << ")");
  laplacian_ = Laplacian(fem, [](int) { return true; });
  if (num_parts > 1) {
    for (int p = 0; p < num_parts; ++p) {
      const SparseMatrix lp = Laplacian(fem, [&](int e) { return part_of_element[e] == p; });
      DIFFPD_CHECK(lp.nonZeros() == laplacian_.nonZeros(), "part Laplacian pattern differs from the mesh's");
      part_laplacian_values_.emplace_back(lp.valuePtr(), lp.valuePtr() + lp.nonZeros());
      part_unit_mass_.push_back(fem.UnitLumpedMass(part_of_element, p));
    }
  }

  for (int d = 0; d < 3; ++d) {
    std::vector<char> mask(n);
    for (int i = 0; i < n; ++i) mask[i] = fixed[3 * i + d];
    int found = -1;
    for (size_t g = 0; g < groups_.size(); ++g)
      if (groups_[g].fixed_node == mask) found = static_cast<int>(g);
    if (found < 0) {
      groups_.push_back(Group{{},
                              mask,
                              SparseMatrix(),
                              std::make_unique<CholmodSolver>(PdFactorLayout(n), CholmodOrdering::kNestedDissection,
                                                              CholmodSolveKernel::kParallelCopy)});
      found = static_cast<int>(groups_.size()) - 1;
    }
    groups_[found].axes.push_back(d);
    group_of_axis_[d] = found;
  }
}

SparseMatrix PdSystem::WeightedLaplacian(const std::vector<double>& weights) const {
  if (AllEqual(weights)) return weights[0] * laplacian_;
  SparseMatrix a = laplacian_;
  Eigen::Map<VectorXd> values(a.valuePtr(), a.nonZeros());
  values.setZero();
  for (int p = 0; p < num_parts_; ++p)
    values += weights[p] * Eigen::Map<const VectorXd>(part_laplacian_values_[p].data(), a.nonZeros());
  return a;
}

VectorXd PdSystem::MassDiagonal(double h, const std::vector<double>& densities) const {
  if (AllEqual(densities)) return (densities[0] / (h * h)) * fem_.unit_lumped_mass();
  VectorXd diag = VectorXd::Zero(fem_.num_nodes());
  for (int p = 0; p < num_parts_; ++p) diag += (densities[p] / (h * h)) * part_unit_mass_[p];
  return diag;
}

bool PdSystem::Update(double h, double rho, double w) {
  return Update(h, std::vector<double>(num_parts_, rho), std::vector<double>(num_parts_, w));
}

bool PdSystem::Update(double h, const std::vector<double>& densities, const std::vector<double>& weights) {
  DIFFPD_CHECK(static_cast<int>(densities.size()) == num_parts_ && static_cast<int>(weights.size()) == num_parts_,
               densities.size() << " densities and " << weights.size() << " weights for " << num_parts_ << " parts");
  if (h == h_ && densities == densities_ && weights == weights_) return false;
  const auto start = std::chrono::steady_clock::now();
  const SparseMatrix weighted = WeightedLaplacian(weights);
  const VectorXd diag = MassDiagonal(h, densities);
  for (Group& g : groups_) {
    g.matrix = weighted;
    if (auxiliary_.size() > 0) g.matrix += auxiliary_;
    g.matrix.diagonal() += diag;
    double* values = g.matrix.valuePtr();
    const int* rows = g.matrix.innerIndexPtr();
    for (int col = 0; col < g.matrix.cols(); ++col)
      for (int t = g.matrix.outerIndexPtr()[col]; t < g.matrix.outerIndexPtr()[col + 1]; ++t)
        if (g.fixed_node[col] || g.fixed_node[rows[t]]) values[t] = rows[t] == col ? 1.0 : 0.0;
    if (!g.solver->Factorize(g.matrix)) {
      h_ = -1;
      std::ostringstream msg;
      msg << "projective dynamics: the matrix A = M/h^2 + w L is not positive definite (h = " << h
          << " s, density = " << densities[0] << ", w = " << weights[0];
      if (num_parts_ > 1) msg << " for the base material; " << num_parts_ - 1 << " material regions";
      msg << ")";
      throw SolverError(SolverStatus::kFactorizationFailed, msg.str());
    }
  }
  ++num_factorizations_;
  factorization_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  h_ = h;
  densities_ = densities;
  weights_ = weights;
  if (!erasures_.empty() || !active_nodes_.empty()) {  // the factor changed: rebuild the erasure on it
    for (ActiveSetErasure& e : erasures_) e.Reset();
    SetActiveNodes(std::vector<int>(active_nodes_), active_mode_);
  }
  return true;
}

void PdSystem::SetSolveThreads(int threads) {
  for (Group& g : groups_) g.solver->set_solve_threads(threads);
}

void PdSystem::SetCopyMaxBytes(double bytes) {
  for (Group& g : groups_) g.solver->set_copy_max_bytes(bytes);
}

std::size_t PdSystem::copy_bytes() const {
  std::size_t bytes = 0;
  for (const Group& g : groups_)
    if (g.solver->parallel_copy()) bytes += g.solver->parallel_copy()->bytes();
  return bytes;
}

double PdSystem::factor_nonzeros() const {
  double entries = 0;
  for (const Group& g : groups_)
    if (g.solver->num_analyses() > 0) entries = std::max(entries, g.solver->factor_nonzeros());
  return entries;
}

double PdSystem::factor_flops() const {
  double flops = 0;
  for (const Group& g : groups_)
    if (g.solver->num_analyses() > 0) flops = std::max(flops, g.solver->factor_flops());
  return flops;
}

double PdSystem::SolveEntries() const {
  const double n = fem_.num_nodes();
  const double erased = static_cast<double>(active_nodes_.size());
  double entries = 0;
  for (size_t gi = 0; gi < groups_.size(); ++gi) {
    const Group& g = groups_[gi];
    if (g.solver->num_analyses() == 0) continue;
    const double factor = g.solver->factor_nonzeros();
    double correction = 0;
    if (gi < erasures_.size() && !erasures_[gi].empty())
      correction = erased <= ActiveSetErasure::kDenseCorrectionMax ? std::min(n * erased, factor) : factor;
    entries += static_cast<double>(g.axes.size()) * (factor + correction);
  }
  return entries;
}

void PdSystem::SetAuxiliaryMatrix(const SparseMatrix& auxiliary) {
  auxiliary_ = auxiliary;
  h_ = -1;
}

void PdSystem::SetActiveNodes(const std::vector<int>& nodes, ContactLinearSolve mode) {
  active_nodes_ = nodes;
  active_mode_ = mode;
  if (h_ < 0) return;  // not factorised yet: applied by Update
  if (erasures_.size() != groups_.size()) erasures_.resize(groups_.size());
  for (size_t gi = 0; gi < groups_.size(); ++gi)
    erasures_[gi].Set(nodes, mode, groups_[gi].matrix, *groups_[gi].solver, groups_[gi].fixed_node);
}

int PdSystem::num_active_set_column_solves() const {
  int total = 0;
  for (const ActiveSetErasure& e : erasures_) total += e.num_column_solves();
  return total;
}

int PdSystem::num_active_set_cached_columns() const {
  int total = 0;
  for (const ActiveSetErasure& e : erasures_) total += e.num_cached_columns();
  return total;
}

int PdSystem::num_active_set_factorizations() const {
  int total = 0;
  for (const ActiveSetErasure& e : erasures_) total += e.num_factorizations();
  return total;
}

MatrixXd PdSystem::Solve(const MatrixXd& r) const {
  const int n = fem_.num_nodes();
  const int cols = static_cast<int>(r.cols());
  MatrixXd out = MatrixXd::Zero(3 * n, cols);
  for (size_t gi = 0; gi < groups_.size(); ++gi) {
    const Group& g = groups_[gi];
    const int na = static_cast<int>(g.axes.size());
    MatrixXd rhs(n, na * cols);
    for (int c = 0; c < cols; ++c)
      for (int a = 0; a < na; ++a)
        for (int i = 0; i < n; ++i) rhs(i, c * na + a) = g.fixed_node[i] ? 0.0 : r(3 * i + g.axes[a], c);
    const bool erased = gi < erasures_.size() && !erasures_[gi].empty();
    const MatrixXd sol = erased ? erasures_[gi].Solve(*g.solver, std::move(rhs)) : g.solver->Solve(rhs);
    for (int c = 0; c < cols; ++c)
      for (int a = 0; a < na; ++a)
        for (int i = 0; i < n; ++i)
          if (!g.fixed_node[i]) out(3 * i + g.axes[a], c) = sol(i, c * na + a);
  }
  return out;
}

VectorXd PdSystem::Solve(const VectorXd& r) const {
  const MatrixXd m = r;
  return Solve(m).col(0);
}

VectorXd PdSystem::Apply(const VectorXd& x) const {
  const int n = fem_.num_nodes();
  VectorXd out = VectorXd::Zero(3 * n);
  for (const Group& g : groups_) {
    for (const int axis : g.axes) {
      VectorXd xa(n);
      for (int i = 0; i < n; ++i) xa(i) = g.fixed_node[i] ? 0.0 : x(3 * i + axis);
      for (const int i : active_nodes_) xa(i) = 0.0;
      VectorXd ya = g.matrix.selfadjointView<Eigen::Lower>() * xa;
      for (const int i : active_nodes_) ya(i) = 0.0;
      for (int i = 0; i < n; ++i)
        if (!g.fixed_node[i]) out(3 * i + axis) = ya(i);
    }
  }
  return out;
}

}  // namespace diffpd::internal
