// The constant matrix of projective dynamics and its factorisation (internal).
//
//   A = M / h^2 + sum_s w_s vol_s G_s^T G_s  =  A_s (x) I_3,
//   A_s = sum_p [(rho_p / h^2) diag(m_p) + w_p L_p],
//   L_p,ab = sum_{s in part p} vol_s grad_a(s) . grad_b(s),
//
// a scalar n x n matrix acting identically on x, y and z; p runs over the
// material parts of the elements (scene/material_regions.h; one part without
// regions), m_p is part p's unit-density lumped mass. When all parts share
// rho and w, A_s = (rho / h^2) diag(m) + w L with the whole mesh's m and L,
// the arithmetic of a single part. Dirichlet DoFs erase rows and columns per
// axis; axes whose fixed-node sets agree share one CHOLMOD factor and are
// solved together as several right-hand sides. The weighted Laplacian is
// reassembled and the factor recomputed exactly when (h, rho_p, w_p) changes
// (the mesh, the parts and the Dirichlet set are fixed for the object's
// lifetime).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "contact/active_set_erasure.h"
#include "diffpd/contact.h"
#include "diffpd/types.h"
#include "fem/fem_model.h"
#include "solver/cholmod_solver.h"

namespace diffpd::internal {

class PdSystem {
 public:
  // `fixed` has 3n flags (DoF 3i + d fixed). `part_of_element` has one part
  // in [0, num_parts) per element, or is empty (one part). Does not take
  // ownership of fem.
  PdSystem(const FemModel& fem, const std::vector<char>& fixed, const std::vector<int>& part_of_element = {},
           int num_parts = 1);

  // Makes the factor current for h (s) and every part's density rho_p
  // (kg/m^3) and weight w_p (Pa), num_parts values each; returns true if it
  // refactorised. Throws SolverError(kFactorizationFailed) if A is not
  // positive definite.
  bool Update(double h, const std::vector<double>& densities, const std::vector<double>& weights);
  // The same with rho and w for every part.
  bool Update(double h, double rho, double w);

  // Solves A dx = r over the free DoFs: returns dx (3n) with zero fixed DoFs.
  // Entries of r at fixed DoFs are ignored. Several vectors: columns of R.
  VectorXd Solve(const VectorXd& r) const;
  MatrixXd Solve(const MatrixXd& r) const;
  // Threads of Solve's triangular solves (>= 1; default 1): the factor's
  // copy is solved in parallel over subtrees of its elimination tree
  // (solver/parallel_triangular_solve.h).
  void SetSolveThreads(int threads);
  // The most bytes the factors' copies may take (CholmodSolver::
  // set_copy_max_bytes); from the next factorisation.
  void SetCopyMaxBytes(double bytes);
  // Bytes of the factors' copies in use (0: none, CHOLMOD solves).
  std::size_t copy_bytes() const;
  // Entries of the largest factor (CholmodSolver::factor_nonzeros; 0 before
  // the first Update).
  double factor_nonzeros() const;
  // Flops of the largest factor's numeric factorisation (CholmodSolver::
  // factor_flops; 0 before the first Update).
  double factor_flops() const;
  // Factor entries one Solve of a single 3n vector passes over, per
  // triangular sweep: every group's factor once per axis it solves, plus the
  // contact active set's correction (ActiveSetErasure: O(n s) for s erased
  // nodes, at most a second solve). A deterministic measure of Solve's cost.
  double SolveEntries() const;
  // y = A x over the free DoFs (fixed rows and columns erased).
  VectorXd Apply(const VectorXd& x) const;

  // A constant scalar n x n term (muscles, penalty contact: sum w G^T G, its
  // pattern within the mesh's) added to A_s; refactorises on the next Update.
  void SetAuxiliaryMatrix(const SparseMatrix& auxiliary);
  // Contact active set: all three axes of `nodes` (sorted) are erased from
  // Solve and Apply as extra fixed DoFs, without refactorising A (see
  // contact/active_set_erasure.h). Empty clears it. Kept across Update.
  void SetActiveNodes(const std::vector<int>& nodes, ContactLinearSolve mode);
  const std::vector<int>& active_nodes() const { return active_nodes_; }
  // Column solves and factorisations spent on active sets so far.
  int num_active_set_column_solves() const;
  int num_active_set_cached_columns() const;  // Woodbury columns held, all groups
  int num_active_set_factorizations() const;

  int num_factorizations() const { return num_factorizations_; }
  // Wall seconds spent in Update's refactorisations (assembly, symbolic
  // analysis and numeric factorisation), all of them so far.
  double factorization_seconds() const { return factorization_seconds_; }
  int num_groups() const { return static_cast<int>(groups_.size()); }

 private:
  struct Group {
    std::vector<int> axes;
    std::vector<char> fixed_node;  // n flags
    SparseMatrix matrix;
    std::unique_ptr<CholmodSolver> solver;
  };
  // sum_p w_p L_p, and the diagonal sum_p (rho_p / h^2) m_p (n).
  SparseMatrix WeightedLaplacian(const std::vector<double>& weights) const;
  VectorXd MassDiagonal(double h, const std::vector<double>& densities) const;

  const FemModel& fem_;
  SparseMatrix laplacian_;
  // With several parts: L_p's values in laplacian_'s pattern, and m_p (n).
  std::vector<std::vector<double>> part_laplacian_values_;
  std::vector<VectorXd> part_unit_mass_;
  int num_parts_ = 1;
  std::vector<Group> groups_;
  std::array<int, 3> group_of_axis_{};
  double h_ = -1;
  std::vector<double> densities_, weights_;
  int num_factorizations_ = 0;
  double factorization_seconds_ = 0;
  SparseMatrix auxiliary_;  // 0 x 0 when none
  std::vector<int> active_nodes_;
  ContactLinearSolve active_mode_ = ContactLinearSolve::kWoodbury;
  std::vector<ActiveSetErasure> erasures_;  // per group, while active_nodes_ is set
};

}  // namespace diffpd::internal
