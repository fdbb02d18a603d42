// Central finite-difference check of a rollout's reverse-mode gradient, with
// a verdict per input kind that separates a wrong gradient from noisy
// differences.
//
// Loss: L = c_x . x_K + c_v . v_K with c_x, c_v fixed pseudo-random vectors
// (seed `seed`), over `steps` steps from `initial` under a baseline of
// per-step external forces (0.1 x a node's weight, random directions) and,
// for scenes with muscles, activations 0.9 + 0.02 N(0,1). For each input kind
// and each of `directions` random directions d (entries of unit root mean
// square), dL/dtheta . d is compared with central differences
//   fd(e) = (L(theta + e s d) - L(theta - e s d)) / 2e
// at the steps e = largest_step, largest_step / 10, ... (step_count of them)
// in units of the input's scale s: x0 the body's size (bounding-box
// diagonal, m); v0 size / h; the per-step external forces m_i size / h^2 /
// sqrt(steps); activations 1 / sqrt(steps); E, rho, the state-force
// parameters their own value (at least 1); nu min(0.1, (0.5 - nu) / 2).
// Input kinds: "x0", "v0", "external_force", "youngs_modulus",
// "poissons_ratio", "density", and where the scene has them "activation",
// "linear_damping", "fluid_density", "drag_tangential", "drag_normal",
// "thrust", "penalty_friction" (all penalty contacts' mu along one direction).
//
// Noise floor: JudgeDerivative (derivative_verdict.h) measures each
// difference's truncation and noise from its neighbours (Richardson-style),
// adds the loss's rounding eps |(c_x,i x_i, |c_v,i| (|v_i| + |x_i| / h))|_2 / e
// (rounding errors of independent sign), picks the step of least
// uncertainty and gives the verdict; where the differences are
// truncation-limited, their Richardson extrapolations may confirm the
// derivative with a larger margin (`extrapolated_directions` counts them).
// The forward's achieved residuals r_k give the worst case of the
// differences' error,
//   (|c_x| + |c_v| / h) sum_k r_k h^2 / m_min / e
// (a residual r moves x by at most r h^2 / m_min); a disagreement within it
// is unresolved, never a failure. An input kind's verdict is the worst over
// its directions.
//
// Wider steps: where the six steps leave a direction unresolved, the
// differences are also taken at 3 and 30 x largest_step (noise falls as 1/e;
// where the loss is nearly linear in the input, e.g. a material parameter
// over a few tiny steps, truncation stays small) and judged again.
//
// Tangent (by default): each direction's derivative is also computed in
// forward mode (Simulator::Tangents) on the checked rollout itself: the
// linearisation of the same steps at the same states, pushed forwards
// instead of transposed, with no truncation and no difference noise. It
// separates "the adjoint is wrong" from "the differences are noisy" where
// the differences cannot: where they resolve the derivative with a margin
// of at least decisive_margin they decide (the tangent is reported); where
// they do not (the loss's rounding, e.g. v = (x_k+1 - x_k) / h at h = 1e-5 s,
// buries a material derivative, or the forward's solves stop at their
// rounding floor, where the computed trajectory is not a smooth function of
// the inputs), the tangent decides when it gives the larger margin: pass
// with margin tolerance / tangent error when the gradient agrees with it
// within the tolerance; fail when it does not and the method is a direct
// Newton one (adjoint and tangent then solve with the same exact Hessian,
// so one of them is wrong); otherwise (iterative solves in both) the input
// stays unresolved, the reason giving the floor and the comparisons.
//
// Frictional contact: the gradient is that of the rollout's smooth piece,
// each step's active set held fixed (contact.h). A perturbed rollout whose
// active set differs at some step lies on another piece: its loss counts as
// non-finite (that difference is not used; the reason counts them, with the
// perturbed rollouts whose solves failed, which count the same), and
// where no step keeps the piece (a node resting exactly on the surface
// leaves the set when lifted by any amount) the tangent, which holds the
// sets fixed as the adjoint does, decides. A reference rollout on another
// piece is not compared (reference_failure says so). The one-sided faces of
// Scene::quad_hydrodynamics make the force jump where a face starts or stops
// meeting the water: every perturbed rollout, and the reference, holds each
// step's faces at the checked rollout's (StepInput::wetted_quads), so that
// the differences are those of the checked rollout's smooth piece, whose
// derivative the adjoint is. That piece still has a kink where a wetted
// face's relative velocity passes through zero (|u| u): differences whose
// perturbed rollouts reversed one cannot fail an input (it is unresolved,
// the reason counts them, and the tangent decides), and decide alone only
// where they pass with a margin of at least widen_below_margin.
//
// Reference: for the iterative methods (pd, pd-lbfgs, newton-pcg) by
// default, the same loss's gradient from a Newton-Cholesky rollout at
// rel_tolerance reference_rel_tolerance is compared too, per direction:
// a reference error above the tolerance fails the input where the
// differences decided (the adjoint, not the differences, is wrong), unless
// they passed with a margin of at least decisive_margin and the method's
// gradient at rel_tolerance / 100 agrees with the reference within the
// tolerance, and better: the disagreement is then the forward's tolerance
// (the gradient is that of the method's own loss, which the differences
// confirm), the margin is the smaller of the differences' and the
// tightened agreement's, and the reason gives both errors. Where
// they did not, the method's gradient is that of its own inexact trajectory
// (e.g. solves stopped at their rounding floor): the tangent decides as
// above and the reason gives the reference error, which says how far that
// trajectory's gradient is from the converged one. A reference that
// converges to another solution of the implicit steps (a node farther than
// reference_trajectory_tolerance x the body's size from the checked
// rollout's at some step) is not compared; reference_failure says so.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/simulator.h"
#include "diffpd/solver_options.h"
#include "tools/derivative_verdict.h"

namespace diffpd::problems {

// One direction of one input kind, judged (GradCheckOptions::progress).
struct GradCheckProgress {
  std::string input;                           // the input kind: "x0", "youngs_modulus", ...
  int direction = 0;                           // which of its directions, from 1
  int directions = 0;                          // how many it has (1 for a scalar parameter)
  CheckVerdict verdict = CheckVerdict::kPass;  // this direction's
  double margin = 0;                           // this direction's tolerance / max(error, floor)
  std::string basis;                           // "differences" or "tangent"
  long perturbed_rollouts = 0;                 // simulated so far in the whole check
};

struct GradCheckOptions {
  int directions = 2;          // random directions per input kind; >= 1
  std::uint64_t seed = 20211;  // seed of the loss, the baseline inputs and the directions
  double tolerance = 1e-4;     // relative tolerance of every verdict; > 0
  double largest_step = 1e-2;  // first step e, in units of the input's scale; > 0
  int step_count = 6;          // steps e, each a tenth of the one before; >= 2
  // Stop taking smaller steps once the differences at the first three (or
  // all, if fewer) pass with at least this margin on their own (not
  // extrapolated, see derivative_verdict.h): the remaining steps
  // could only lower the floor of a derivative already resolved (its
  // reported margin is then a lower bound). Halves the rollouts of a clean
  // check. 0: always take all step_count steps.
  double early_stop_margin = 10;
  // Compare with a Newton-Cholesky rollout's gradient; unset: for pd,
  // pd-lbfgs and newton-pcg (never for semi-implicit, whose time
  // discretisation differs).
  std::optional<bool> reference;
  double reference_rel_tolerance = 1e-12;  // of the reference's forward and adjoint solves
  // The reference is not compared where any of its steps puts a node
  // farther than this (units of the body's size, the bounding-box diagonal)
  // from the checked rollout's: the implicit steps have another solution
  // there (reference_failure says so). Finite and > 0.
  double reference_trajectory_tolerance = 1e-2;
  // Where the differences leave an input unresolved, also take them at two
  // larger steps (3 and 30 x largest_step), evaluations that fail counting
  // as non-finite: noise falls as 1/e, and the Richardson estimate tells
  // whether truncation allows the larger step.
  bool widen_steps = true;
  // With widen_steps, differences that pass with a margin below this are
  // widened too, and the wider judgement kept where it passes with a larger
  // margin (a derivative the loss's rounding nearly buries, e.g. a material
  // parameter over a few tiny steps). Finite and >= 1.
  double widen_below_margin = 10;
  // Compare with the forward-mode tangent (Simulator::Tangents) of the
  // checked rollout; where the differences do not decide, it does (see above).
  bool tangent = true;
  // Differences that pass with at least this margin decide alone; below it,
  // or unresolved, the tangent decides where it gives the larger margin.
  // Finite and >= 1.
  double decisive_margin = 10;
  // Perturbed rollouts simulated at once, in [1, MaxSolverThreads()]. 1:
  // one after the other on the checked rollout's simulator, with the
  // options' num_threads. Above 1: each on a simulator of its own (one per
  // rollout at once, so memory grows by as many simulators) on one thread;
  // the same rollouts and, up to rounding, the same differences, but which
  // thread runs which rollout changes that rounding (and each simulator's
  // SVD warm starts carry over from the rollout it ran before), so errors,
  // floors and margins at the differences' noise level differ from run to
  // run.
  int concurrent_rollouts = 1;
  // Called on the calling thread after each direction is judged, e.g. to
  // print progress through a long check; empty: not called. Must not throw.
  std::function<void(const GradCheckProgress&)> progress;

  // Throws InvalidInputError naming the field, its value and the valid range.
  void Validate() const;
};

struct GradCheckInput {
  std::string input;  // "x0", "v0", "external_force", "youngs_modulus", ...
  long entries = 0;   // number of scalar inputs of this kind
  int directions = 0;
  CheckVerdict verdict = CheckVerdict::kPass;  // worst over the directions (differences and reference)
  // error, floor and bound: the largest over the directions the differences
  // decided (over every direction where the tangent decided them all).
  double error = 0;   // relative error against the differences
  double floor = 0;   // relative noise floor of the differences
  double bound = 0;   // relative worst case from the residuals
  double margin = 0;  // smallest tolerance / max(error, floor)
  double step = 0;    // the step of the worst direction (units of the scale)
  // Largest relative difference from the reference gradient; NaN: not compared.
  double reference_error = 0;
  // Where the differences passed decisively but the reference disagreed:
  // the largest relative difference from the reference of the method's
  // gradient with its forward solves at rel_tolerance / 100; NaN: not
  // computed.
  double tightened_reference_error = std::numeric_limits<double>::quiet_NaN();
  // Largest relative difference from the forward-mode tangent; NaN: not
  // compared (or its pass failed).
  double tangent_error = 0;
  // What the verdict rests on: "differences", or "tangent" where the
  // differences could not resolve some direction (worst direction's basis).
  std::string basis = "differences";
  int tangent_directions = 0;  // directions the tangent decided
  // Directions the differences decided on their Richardson extrapolations
  // (DerivativeJudgement::extrapolated).
  int extrapolated_directions = 0;
  std::string reason;  // empty for a pass: why the worst direction failed or is unresolved
};

struct GradCheckResult {
  std::string method;             // the checked method (ToString)
  double tolerance = 0;           // GradCheckOptions::tolerance
  bool reference = false;         // whether the Newton-Cholesky reference was compared
  bool tangent = false;           // whether the forward-mode tangent was compared
  std::string reference_failure;  // non-empty: the reference rollout failed (its error); not compared
  std::vector<GradCheckInput> inputs;
  CheckVerdict verdict = CheckVerdict::kPass;  // worst over the inputs
  double max_error = 0;                        // over the inputs
  double min_margin = 0;                       // over the inputs
  long perturbed_rollouts = 0;                 // rollouts simulated for the differences (the check's cost)
  // Semi-implicit only (NaN otherwise): its stability limit at the initial
  // state (Simulator::ExplicitStableTimeStep, s) and the checked step h (s).
  // Above it the rollout grows without bound: the gradient is that of a
  // diverging trajectory, and the table and JSON say so.
  double explicit_stable_time_step = std::numeric_limits<double>::quiet_NaN();
  double time_step = 0;

  int Count(CheckVerdict verdict) const;
};

// Runs the check with the solver options as given (make tolerances tight:
// the noise floor follows the residuals the solves reach). Throws
// InvalidInputError on bad check options, SolverError from the checked
// method's own solves.
GradCheckResult CheckRolloutGradient(const Scene& scene, const SolverOptions& options, const State& initial, int steps,
                                     const GradCheckOptions& check = GradCheckOptions());

// CheckRolloutGradient at options.rel_tolerance or, where the checked
// method cannot reach it within options.max_iterations (SolverError with
// status kMaxIterations: plain pd's linear convergence on a stiff beam), at
// the tightest of rel_tolerance x 100, x 10^4, ... up to loosest_rel_tolerance
// that it reaches; its differences' floor then follows that tolerance.
// *used_rel_tolerance (if not null) receives the tolerance checked at.
// Rethrows the last SolverError where none is reached, and any other.
GradCheckResult CheckRolloutGradientAtReachableTolerance(const Scene& scene, const SolverOptions& options,
                                                         const State& initial, int steps, const GradCheckOptions& check,
                                                         double loosest_rel_tolerance, double* used_rel_tolerance);

// The solve tolerance `diffpd gradcheck` recommends for a method: tight enough
// that the differences resolve the gradient to well within 1e-4.
double RecommendedGradCheckRelTolerance(Method method);
// The time step `diffpd gradcheck` checks a method at, given a simulator of
// `scene` with the problem's own step in its options (s): that step, except
// for semi-implicit Euler where it is above half the stability limit at
// `initial` (Simulator::ExplicitStableTimeStep with the muscles at 0.9, the
// check's baseline): there half that limit, rounded down to two
// significant digits. Above the limit the rollout grows without bound, and
// the limit ignores damping, the state forces and the motion, hence the half.
double RecommendedGradCheckTimeStep(const Scene& scene, Simulator& sim, const State& initial);
// The iteration limit per step `diffpd gradcheck` gives a method's solves:
// 10000 for pd, whose local-global iteration converges linearly (the
// library's default of 1000 stops it short of 1e-10 on the routing tendon,
// bunny, quadruped and cow; on the full cantilever it takes about 7200 per
// step), 1000 (the default) for the others.
int RecommendedGradCheckMaxIterations(Method method);

// Reports made from a result: a table (one line per input and a summary
// line) and one JSON object with the same fields.
std::string GradCheckTable(const GradCheckResult& result);
nlohmann::json GradCheckToJson(const GradCheckResult& result);

}  // namespace diffpd::problems
