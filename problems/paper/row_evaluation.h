// One evaluation of a paper row's loss (and gradient) at a point, the
// random-draw normalisation, and the normalised loss.
#pragma once

#include <vector>

#include "diffpd/simulator.h"
#include "paper/paper_row.h"

namespace diffpd::problems {

// What RowEvaluation's seconds count: wall time, or the process's CPU time
// (steadier on a loaded machine with one thread; with more it includes
// OpenMP's spinning).
enum class RowClock { kWall, kCpu };

struct RowEvaluation {
  double loss = 0;
  VectorXd gradient;                        // dL/dx (num_variables); empty when not requested
  double forward_s = 0;                     // seconds of Simulator::Simulate (a material change refactorises here)
  double backward_s = 0;                    // seconds of Simulator::Backward and the pull-back
  double iterations_per_step = 0;           // forward solver iterations per step
  int newton_fallback_steps = 0;            // PD-LBFGS steps finished by Newton
  double backward_iterations_per_step = 0;  // adjoint solver iterations per step (0: direct solves)
  int backward_fallbacks = 0;               // adjoint solves that fell back to a direct solve
  int backward_indefinite_steps = 0;        // steps whose Hessian was indefinite (BackwardReport)
};

// Simulates the row at variables x with `simulator` (made from row.scene; its
// material is set from the setup when it differs) and evaluates the loss;
// with `gradient`, also the backward pass and dL/dx; the seconds by `clock`.
// A row with a controller block runs closed loop. Throws InvalidInputError
// if the row still needs PaperRow::Prepare or x has the wrong size, and
// SolverError when a solve fails.
RowEvaluation EvaluateRow(const PaperRow& row, Simulator* simulator, const VectorXd& x, bool gradient,
                          RowClock clock = RowClock::kWall);

// Losses of the row's random draws (forward only), in order.
std::vector<double> RandomDrawLosses(const PaperRow& row, Simulator* simulator);

// (L - l) / (L_random - l).
double NormalisedLoss(double loss, double random_mean, double baseline);

}  // namespace diffpd::problems
