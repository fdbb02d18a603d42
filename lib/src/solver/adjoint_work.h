// Deterministic cost estimates of the two adjoint solvers between which
// SolverOptions::adjoint_solver = kAuto chooses (internal; the choice is
// adjoint_cost_model.h's). Costs are in seconds of one core of a reference
// machine, from counts and sizes of the problem only (never from clocks), so
// that the choice is the same on every run of the same problem.
//
// The iteration: every product with H reads the packed element Hessians
// once; every solve with A's factors passes PdSystem::SolveEntries() factor
// entries forward and back per vector; every iteration makes a few vector
// passes over the 3n DoFs; every solve has a set-up. The factorisation:
// CHOLMOD's numeric factorisation (its flop count, and a cost per factor
// entry), the assembly and bookkeeping per DoF, and a forward and back solve
// per right-hand side. Its one-off symbolic analysis (with the first
// factorisation's set-up) costs a call and a cost per factor entry. Before H's first analysis its factor is estimated
// from A's: H is A's pattern with 3 x 3 blocks, so about 9 times the entries and 27 times the flops.
#pragma once

namespace diffpd::internal {

// The sizes the estimates need.
struct AdjointWorkSizes {
  double dofs = 0;              // 3n
  double packed_entries = 0;    // entries of the packed element Hessians
  double pd_solve_entries = 0;  // PdSystem::SolveEntries()
  // H's factor: its entries and the flops of one numeric factorisation
  // (estimated from A's before H is analysed), and whether the analysis is
  // still to come.
  double hessian_factor_entries = 0;
  double hessian_factor_flops = 0;
  bool hessian_analysed = false;
};

// What one iterative solve did (all right-hand sides together).
struct IterativeWork {
  double hessian_products = 0;  // single-vector products with H
  double pd_solves = 0;         // single-vector solves with A's factors
  double iterations = 0;        // iterations summed over the right-hand sides
};

// Estimated seconds of the iterative solve that did `work`.
double IterativeSeconds(const AdjointWorkSizes& sizes, const IterativeWork& work);
// Estimated seconds of one step's direct solve of `columns` right-hand
// sides: assembly, numeric factorisation and solves (without the analysis).
double DirectSeconds(const AdjointWorkSizes& sizes, int columns);
// Estimated seconds of the one-off symbolic analysis of H.
double AnalysisSeconds(const AdjointWorkSizes& sizes);

}  // namespace diffpd::internal
