#include "solver/pd_system.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {

PdSystem::PdSystem(const FemModel& fem, const std::vector<char>& fixed) : fem_(fem) {
  const int n = fem.num_nodes();
  const int k = fem.nodes_per_element();
  const Mesh& mesh = fem.mesh();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(fem.num_elements()) * k * k);
  for (int e = 0; e < fem.num_elements(); ++e) {
    Eigen::MatrixXd le = Eigen::MatrixXd::Zero(k, k);
    for (int q = 0; q < fem.samples_per_element(); ++q) {
      const int s = e * fem.samples_per_element() + q;
      const Eigen::Map<const Eigen::MatrixXd> g(fem.grad(s), k, 3);
      le.noalias() += fem.sample_volume(s) * g * g.transpose();
    }
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) triplets.emplace_back(mesh.elements(a, e), mesh.elements(b, e), le(a, b));
  }
  laplacian_.resize(n, n);
  laplacian_.setFromTriplets(triplets.begin(), triplets.end());
  laplacian_.makeCompressed();

  for (int d = 0; d < 3; ++d) {
    std::vector<char> mask(n);
    for (int i = 0; i < n; ++i) mask[i] = fixed[3 * i + d];
    int found = -1;
    for (size_t g = 0; g < groups_.size(); ++g)
      if (groups_[g].fixed_node == mask) found = static_cast<int>(g);
    if (found < 0) {
      groups_.push_back(Group{{}, mask, SparseMatrix(), std::make_unique<CholmodSolver>()});
      found = static_cast<int>(groups_.size()) - 1;
    }
    groups_[found].axes.push_back(d);
    group_of_axis_[d] = found;
  }
}

bool PdSystem::Update(double h, double rho, double w) {
  if (h == h_ && rho == rho_ && w == w_) return false;
  const VectorXd diag = (rho / (h * h)) * fem_.unit_lumped_mass();
  for (Group& g : groups_) {
    g.matrix = w * laplacian_;
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
          << " s, density = " << rho << ", w = " << w << ")";
      throw SolverError(SolverStatus::kFactorizationFailed, msg.str());
    }
  }
  ++num_factorizations_;
  h_ = h;
  rho_ = rho;
  w_ = w;
  if (!erasures_.empty() || !active_nodes_.empty()) {  // the factor changed: rebuild the erasure on it
    for (ActiveSetErasure& e : erasures_) e.Reset();
    SetActiveNodes(std::vector<int>(active_nodes_), active_mode_);
  }
  return true;
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
