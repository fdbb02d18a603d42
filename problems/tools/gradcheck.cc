#include "tools/gradcheck.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <random>

#include <omp.h>

#include "cli/invalid_option.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/wetted_quads.h"
#include "tools/stress.h"

namespace diffpd::problems {
namespace {

VectorXd RandomVector(std::mt19937_64* rng, Eigen::Index n) {
  std::normal_distribution<double> normal(0.0, 1.0);
  VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

// Random, entries of unit root mean square.
VectorXd Direction(std::mt19937_64* rng, Eigen::Index n) {
  const VectorXd d = RandomVector(rng, n);
  return d * (std::sqrt(double(n)) / d.norm());
}

// Steps taken before the early stop is considered (GradCheckOptions::early_stop_margin).
constexpr int kEarlyStopSteps = 3;

bool UsesReferenceByDefault(Method m) { return m == Method::kPd || m == Method::kPdLbfgs || m == Method::kNewtonPcg; }
// |a - b| / max(|a|, |b|); 0 where both are 0.
double RelativeDifference(double a, double b) {
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale > 0 ? std::abs(a - b) / scale : 0.0;
}

// Newton with a direct solve: its adjoint is exact for its own trajectory.
bool IsDirectNewton(Method m) { return m == Method::kNewtonCholesky || m == Method::kNewtonLdlt; }

// Thrown by a perturbed rollout that lies on another piece of a frictional
// contact trajectory (its active set differs from the checked rollout's).
struct OtherPiece {};

// Thrown, with its loss, by a perturbed rollout in which a wetted quad face's
// relative velocity (Scene::quad_hydrodynamics) passed through zero.
struct FaceReversal {
  double loss;
};

// The losses of a check: the loss vectors, the baseline inputs and the
// gradient of one method's rollout.
struct Evaluation {
  VectorXd cx, cv;
  std::vector<StepInput> inputs;
  RolloutGradient gradient;
};

}  // namespace

void GradCheckOptions::Validate() const {
  const auto fail = ThrowInvalidOption;
  if (directions < 1) fail("directions", directions, ">= 1");
  if (!(tolerance > 0 && std::isfinite(tolerance))) fail("tolerance", tolerance, "finite and > 0");
  if (!(largest_step > 0 && std::isfinite(largest_step))) fail("largest_step", largest_step, "finite and > 0");
  if (step_count < 2) fail("step_count", step_count, ">= 2");
  if (!(early_stop_margin == 0 || (early_stop_margin >= 1 && std::isfinite(early_stop_margin))))
    fail("early_stop_margin", early_stop_margin, "0 or finite and >= 1");
  if (!(widen_below_margin >= 1 && std::isfinite(widen_below_margin)))
    fail("widen_below_margin", widen_below_margin, "finite and >= 1");
  if (!(decisive_margin >= 1 && std::isfinite(decisive_margin)))
    fail("decisive_margin", decisive_margin, "finite and >= 1");
  if (!(reference_rel_tolerance > 0 && reference_rel_tolerance < 1))
    fail("reference_rel_tolerance", reference_rel_tolerance, "in (0, 1)");
  if (!(reference_trajectory_tolerance > 0 && std::isfinite(reference_trajectory_tolerance)))
    fail("reference_trajectory_tolerance", reference_trajectory_tolerance, "finite and > 0");
  if (concurrent_rollouts < 1 || concurrent_rollouts > MaxSolverThreads())
    fail("concurrent_rollouts", concurrent_rollouts, "in [1, " + std::to_string(MaxSolverThreads()) + "]");
}

int GradCheckResult::Count(CheckVerdict v) const {
  int count = 0;
  for (const auto& e : inputs) count += e.verdict == v;
  return count;
}

double RecommendedGradCheckRelTolerance(Method method) {
  // The differences' measured floor stays far below the check's 1e-4 at
  // these (measured on every problem, docs/benchmarks.md); PD converges
  // linearly, so a looser tolerance saves most of its iterations.
  return method == Method::kPd ? 1e-10 : 1e-11;
}

double RecommendedGradCheckTimeStep(const Scene& scene, Simulator& sim, const State& initial) {
  const SolverOptions& options = sim.options();
  if (options.method != Method::kSemiImplicit) return options.time_step;
  const double half_limit =
      0.5 *
      sim.ExplicitStableTimeStep(initial.x, VectorXd::Constant(static_cast<Eigen::Index>(scene.muscles.size()), 0.9));
  if (!(options.time_step > half_limit)) return options.time_step;
  // Two significant digits, rounded down: a step that reads well.
  const double scale = std::pow(10.0, 1 - std::floor(std::log10(half_limit)));  // exact for the steps in use
  return std::floor(half_limit * scale) / scale;
}

int RecommendedGradCheckMaxIterations(Method method) {
  return method == Method::kPd ? 10000 : SolverOptions().max_iterations;
}

GradCheckResult CheckRolloutGradient(const Scene& scene, const SolverOptions& options, const State& initial, int steps,
                                     const GradCheckOptions& check) {
  check.Validate();
  if (steps < 1) ThrowInvalidOption("steps", steps, ">= 1");
  std::mt19937_64 rng(check.seed);
  Simulator sim(scene, options);
  const int n = sim.num_dofs();
  const double h = options.time_step;
  const VectorXd mass = sim.LumpedMass();
  Evaluation base;
  base.cx = RandomVector(&rng, n);
  base.cv = RandomVector(&rng, n);
  base.inputs.resize(steps);
  const double node_force = mass.maxCoeff() * 9.81;
  for (auto& in : base.inputs) in.external_force = 0.1 * node_force * RandomVector(&rng, n);
  const int num_muscles = static_cast<int>(scene.muscles.size());
  if (num_muscles > 0)
    for (auto& in : base.inputs)
      in.activation = VectorXd::Constant(num_muscles, 0.9) + 0.02 * RandomVector(&rng, num_muscles);
  const VectorXd &cx = base.cx, &cv = base.cv;
  auto loss_of = [&](const State& last) { return cx.dot(last.x) + cv.dot(last.v); };
  LossGradient dl(steps);
  dl.dx[steps] = cx;
  dl.dv[steps] = cv;
  const Rollout rollout = sim.Simulate(initial, base.inputs);
  const RolloutGradient grad = sim.Backward(rollout, dl);
  Eigen::Map<const Eigen::Matrix3Xd> x0(initial.x.data(), 3, n / 3);
  const double size = (x0.rowwise().maxCoeff() - x0.rowwise().minCoeff()).norm();  // m
  // The one-sided faces of Scene::quad_hydrodynamics: the force jumps where a
  // face starts or stops meeting the water. Every other rollout of the check
  // holds each step's faces at the checked rollout's, so that it lies on the
  // checked rollout's smooth piece, whose derivative the adjoint is. That
  // piece is not smooth where a wetted face's relative velocity passes
  // through zero: whether a rollout reversed one (u . u_checked <= 0).
  std::vector<Eigen::Matrix3Xd> face_velocities;  // the checked rollout's, per step
  if (scene.quad_hydrodynamics)
    for (int k = 0; k < steps; ++k) {
      base.inputs[k].wetted_quads = WettedQuads(*scene.quad_hydrodynamics, rollout.states[k].x, rollout.states[k].v);
      face_velocities.push_back(QuadRelativeVelocities(*scene.quad_hydrodynamics, rollout.states[k].v));
    }
  const std::vector<StepInput>& inputs = base.inputs;
  auto reverses_a_face = [&](const Rollout& r) {
    for (size_t k = 0; k < face_velocities.size() && k < r.states.size(); ++k) {
      const Eigen::Matrix3Xd u = QuadRelativeVelocities(*scene.quad_hydrodynamics, r.states[k].v);
      for (Eigen::Index f = 0; f < u.cols(); ++f)
        if (inputs[k].wetted_quads[f] && u.col(f).dot(face_velocities[k].col(f)) <= 0) return true;
    }
    return false;
  };
  // With frictional contact the gradient is that of the rollout's smooth
  // piece, its active sets held fixed (contact.h): a rollout whose sets
  // differ lies on another piece. Returns the first step whose set differs
  // from the checked rollout's, or -1.
  auto other_piece = [&](const Rollout& r) {
    for (size_t k = 0; k < r.reports.size() && k < rollout.reports.size(); ++k)
      if (r.reports[k].contact_nodes != rollout.reports[k].contact_nodes) return static_cast<int>(k);
    return -1;
  };
  int set_changes = 0;     // perturbed rollouts that left the piece (their differences count as non-finite)
  int face_reversals = 0;  // perturbed rollouts that reversed a wetted quad face's relative velocity

  GradCheckResult result;
  result.method = ToString(options.method);
  result.tolerance = check.tolerance;
  result.time_step = h;
  if (options.method == Method::kSemiImplicit)
    result.explicit_stable_time_step = sim.ExplicitStableTimeStep(initial.x, inputs.front().activation);
  result.reference = check.reference.value_or(UsesReferenceByDefault(options.method));
  result.tangent = check.tangent;
  RolloutGradient reference;
  if (result.reference) {
    SolverOptions tight = options;
    tight.method = Method::kNewtonCholesky;
    tight.rel_tolerance = check.reference_rel_tolerance;
    tight.backward_rel_tolerance = check.reference_rel_tolerance;
    tight.abs_tolerance = std::min(options.abs_tolerance, AutoAbsTolerance(scene, h));
    tight.max_iterations = std::max(options.max_iterations, 200);
    try {
      Simulator newton(scene, tight);
      const Rollout converged = newton.Simulate(initial, inputs);
      const int k = other_piece(converged);
      if (k >= 0) {
        result.reference = false;
        result.reference_failure = "its contact active set differs from the checked rollout's at step " +
                                   std::to_string(k + 1) + " (another piece of the trajectory): not compared";
      } else {
        // Where the implicit steps have more than one solution (soft
        // material crushed at large h), the reference may converge to
        // another: its gradient is another trajectory's.
        int apart = -1;
        double distance = 0;
        for (size_t k = 1; k < converged.states.size() && apart < 0; ++k) {
          distance = (converged.states[k].x - rollout.states[k].x).lpNorm<Eigen::Infinity>() / size;
          if (!(distance <= check.reference_trajectory_tolerance)) apart = static_cast<int>(k);
        }
        if (apart >= 0) {
          result.reference = false;
          result.reference_failure = "its trajectory is another solution of the implicit steps: a node " +
                                     FormatTwoDigits(distance) +
                                     " of the body's size from the checked rollout's at step " + std::to_string(apart) +
                                     " (reference_trajectory_tolerance " +
                                     FormatTwoDigits(check.reference_trajectory_tolerance) + "): not compared";
        } else {
          reference = newton.Backward(converged, dl);
        }
      }
    } catch (const SolverError& e) {
      result.reference = false;
      result.reference_failure = std::string(ToString(e.status())) + ": " + e.what();
    }
  }
  // The method's own gradient with its forward solves 100x tighter, computed
  // once, where a disagreement with the reference must be told apart from
  // the forward's tolerance; nullopt where those solves fail or the rollout
  // leaves the checked one's piece.
  const double tightened_rel_tolerance = options.rel_tolerance / 100;
  std::optional<std::optional<RolloutGradient>> tightened;
  auto tightened_gradient = [&]() -> const std::optional<RolloutGradient>& {
    if (!tightened) {
      tightened.emplace();
      SolverOptions tighter = options;
      tighter.rel_tolerance = tightened_rel_tolerance;
      try {
        Simulator s(scene, tighter);
        const Rollout r = s.Simulate(initial, inputs);
        if (other_piece(r) < 0) *tightened = s.Backward(r, dl);
      } catch (const SolverError&) {
      }
    }
    return *tightened;
  };
  // The loss's derivative along `direction` in forward mode on the checked
  // rollout's states; NaN when the tangent pass fails. Every implicit method
  // solves the same implicit Euler step, so its exact linearisation is
  // solved directly, by Newton-Cholesky, at the method's own states.
  std::unique_ptr<Simulator> tangent_sim;
  Rollout tangent_rollout;
  if (result.tangent && options.method != Method::kSemiImplicit) {
    SolverOptions direct = options;
    direct.method = Method::kNewtonCholesky;
    tangent_sim = std::make_unique<Simulator>(scene, direct);
    tangent_rollout = rollout;
    tangent_rollout.options.method = Method::kNewtonCholesky;
  }
  auto tangent_of = [&](const InputDirection& direction) {
    if (!result.tangent) return std::numeric_limits<double>::quiet_NaN();
    try {
      const TangentRollout t =
          tangent_sim ? tangent_sim->Tangents(tangent_rollout, {direction}) : sim.Tangents(rollout, {direction});
      return cx.dot(t.dx[steps].col(0)) + cv.dot(t.dv[steps].col(0));
    } catch (const std::exception&) {
      return std::numeric_limits<double>::quiet_NaN();
    }
  };

  // Rounding of one evaluation of the loss and the worst case of its error
  // from the solves (see the header).
  const State& last = rollout.states.back();
  const VectorXd loss_terms_v = cv.cwiseAbs().cwiseProduct(last.v.cwiseAbs() + last.x.cwiseAbs() / h);
  const double rounding = std::numeric_limits<double>::epsilon() *
                          std::sqrt(cx.cwiseProduct(last.x).squaredNorm() + loss_terms_v.squaredNorm());
  double solve_error_x = 0;
  for (const auto& rep : rollout.reports) solve_error_x += rep.final_residual * h * h / mass.minCoeff();
  const double solve_bound = (cx.norm() + cv.norm() / h) * solve_error_x;

  // The simulators of the perturbed rollouts, one per rollout at once: the
  // checked rollout's own when they run one at a time, otherwise one each,
  // on one thread. The loss of a rollout throws OtherPiece where it leaves
  // the checked rollout's piece.
  SolverOptions worker_options = options;
  worker_options.num_threads = 1;
  std::vector<std::unique_ptr<Simulator>> own_workers;
  std::vector<Simulator*> workers = {&sim};
  if (check.concurrent_rollouts > 1) {
    workers.clear();
    for (int w = 0; w < check.concurrent_rollouts; ++w) {
      own_workers.push_back(std::make_unique<Simulator>(scene, worker_options));
      workers.push_back(own_workers.back().get());
    }
  }
  const SolverOptions& perturbed_options = check.concurrent_rollouts > 1 ? worker_options : options;
  auto rollout_loss = [&](Simulator& s, const State& init, const std::vector<StepInput>& in) {
    const Rollout r = s.Simulate(init, in);
    if (other_piece(r) >= 0) throw OtherPiece();
    if (reverses_a_face(r)) throw FaceReversal{loss_of(r.states.back())};
    return loss_of(r.states.back());
  };
  // perturbed(simulator, e) at every e of `at`, check.concurrent_rollouts at
  // a time, each on its worker's simulator. A rollout on another piece gives
  // NaN and counts in set_changes; so does one whose solves fail
  // (SolverError), counted unless tolerate_all; with tolerate_all every other
  // exception gives NaN too, without it the first (in the order of `at`) is
  // rethrown.
  auto losses = [&](const std::function<double(Simulator&, double)>& perturbed, const std::vector<double>& at,
                    bool tolerate_all) {
    const int m = static_cast<int>(at.size());
    std::vector<double> values(m, std::numeric_limits<double>::quiet_NaN());
    std::vector<char> counted(m, 0), reversed(m, 0);
    std::vector<std::exception_ptr> errors(m);
    const int count = static_cast<int>(workers.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(count) if (count > 1)
    for (int i = 0; i < m; ++i) {
      try {
        values[i] = perturbed(*workers[count > 1 ? omp_get_thread_num() : 0], at[i]);
      } catch (const FaceReversal& e) {
        values[i] = e.loss;
        reversed[i] = 1;
      } catch (const OtherPiece&) {
        counted[i] = 1;
      } catch (const SolverError&) {
        counted[i] = !tolerate_all;
      } catch (...) {
        if (!tolerate_all) errors[i] = std::current_exception();
      }
    }
    result.perturbed_rollouts += m;
    for (int i = 0; i < m; ++i) {
      if (errors[i]) std::rethrow_exception(errors[i]);
      set_changes += counted[i];
      face_reversals += reversed[i];
    }
    return values;
  };

  // One direction of one input kind: perturbed(e) is the loss with the input
  // moved by e (units of its scale along the direction); analytic and
  // reference are the derivatives along the same.
  auto record = [&](const std::string& name, long entries, int directions,
                    const std::function<double(const RolloutGradient&)>& along, double tangent_value,
                    const std::function<double(Simulator&, double)>& perturbed) {
    const double analytic = along(grad);
    const double reference_value = result.reference ? along(reference) : 0.0;
    GradCheckInput* entry = nullptr;
    for (auto& e : result.inputs)
      if (e.input == name) entry = &e;
    if (!entry) {
      GradCheckInput fresh;
      fresh.input = name;
      fresh.entries = entries;
      fresh.margin = std::numeric_limits<double>::infinity();
      fresh.reference_error = result.reference ? 0.0 : std::numeric_limits<double>::quiet_NaN();
      fresh.tangent_error = result.tangent ? 0.0 : std::numeric_limits<double>::quiet_NaN();
      fresh.tightened_reference_error = std::numeric_limits<double>::quiet_NaN();
      result.inputs.push_back(fresh);
      entry = &result.inputs.back();
    }
    const int changes_before = set_changes, reversals_before = face_reversals;
    std::vector<FiniteDifference> differences;
    double e = check.largest_step;
    // Takes the next steps, each a tenth of the one before, up to `count` in
    // all. A perturbed rollout whose solves fail (e.g. a contact step that
    // would gain energy from a perturbed state) gives no difference:
    // non-finite.
    auto take_steps = [&](int count) {
      std::vector<double> at;
      double step = e;
      for (int k = static_cast<int>(differences.size()); k < count; ++k, step /= 10) {
        at.push_back(step);
        at.push_back(-step);
      }
      const std::vector<double> loss = losses(perturbed, at, /*tolerate_all=*/false);
      for (size_t i = 0; i < at.size(); i += 2, e /= 10)
        differences.push_back({e, (loss[i] - loss[i + 1]) / (2 * e), rounding / e, solve_bound / e});
      return JudgeDerivative(analytic, differences, check.tolerance);
    };
    const bool may_stop_early = check.early_stop_margin > 0 && kEarlyStopSteps < check.step_count;
    DerivativeJudgement j = take_steps(may_stop_early ? kEarlyStopSteps : check.step_count);
    if (may_stop_early) {
      // Decided on the differences themselves: an extrapolation from the
      // first steps alone is less certain than the smaller steps would be.
      const DerivativeJudgement first = JudgeDerivative(analytic, differences, check.tolerance, /*extrapolate=*/false);
      if (!(first.verdict == CheckVerdict::kPass && first.margin >= check.early_stop_margin))
        j = take_steps(check.step_count);
    }
    const bool weak_pass = j.verdict == CheckVerdict::kPass && j.margin < check.widen_below_margin;
    if ((j.verdict == CheckVerdict::kUnresolved || weak_pass) && check.widen_steps) {
      // Larger steps, where the perturbed input may leave the scene's valid
      // range or the solver's reach: such a difference counts as non-finite.
      const double w30 = 30.0 * check.largest_step, w3 = 3.0 * check.largest_step;
      const std::vector<double> loss = losses(perturbed, {w30, -w30, w3, -w3}, /*tolerate_all=*/true);
      std::vector<FiniteDifference> wider;
      wider.push_back({w30, (loss[0] - loss[1]) / (2 * w30), rounding / w30, solve_bound / w30});
      wider.push_back({w3, (loss[2] - loss[3]) / (2 * w3), rounding / w3, solve_bound / w3});
      wider.insert(wider.end(), differences.begin(), differences.end());
      const DerivativeJudgement widened = JudgeDerivative(analytic, wider, check.tolerance);
      if (weak_pass ? widened.verdict == CheckVerdict::kPass && widened.margin > j.margin
                    : widened.verdict == CheckVerdict::kPass || widened.floor < j.floor)
        j = widened;
    }
    CheckVerdict verdict = j.verdict;
    std::string reason = j.reason;
    if (set_changes > changes_before && verdict != CheckVerdict::kPass)
      reason += "; " + std::to_string(set_changes - changes_before) +
                " perturbed rollouts changed the contact active set or failed (no difference there)";
    // Differences across a wetted face's zero relative velocity straddle the
    // force's kink (|u| u, the angle's jump): they cannot fail an input, and
    // decide alone only with a margin of at least widen_below_margin.
    const int reversals = face_reversals - reversals_before;
    const std::string kink = std::to_string(reversals) +
                             " perturbed rollouts reversed a wetted quad face's relative velocity (the force is not "
                             "smooth where it passes through zero)";
    if (reversals > 0 && verdict != CheckVerdict::kPass) {
      verdict = CheckVerdict::kUnresolved;
      reason = kink + "; differences: " + reason;
    }
    const double decisive =
        reversals > 0 ? std::max(check.decisive_margin, check.widen_below_margin) : check.decisive_margin;
    std::string basis = "differences";
    double margin = j.margin;
    double tangent_error = std::numeric_limits<double>::quiet_NaN();
    if (result.tangent && std::isfinite(tangent_value)) {
      tangent_error = RelativeDifference(analytic, tangent_value);
      entry->tangent_error = std::max(entry->tangent_error, tangent_error);
    }
    const bool weak = verdict == CheckVerdict::kUnresolved || (verdict == CheckVerdict::kPass && j.margin < decisive);
    const bool tangent_decides = weak && std::isfinite(tangent_error);
    const double tangent_margin =
        tangent_error > 0 ? check.tolerance / tangent_error : std::numeric_limits<double>::infinity();
    if (tangent_decides && tangent_error <= check.tolerance && tangent_margin > j.margin) {
      verdict = CheckVerdict::kPass;
      basis = "tangent";
      margin = tangent_margin;
      reason = (j.verdict == CheckVerdict::kPass ? "differences pass with margin " + FormatTwoDigits(j.margin) + " only"
                                                 : "differences unresolved (" + j.reason + ")") +
               (reversals > 0 ? "; " + kink : "") + "; agrees with the forward-mode tangent to " +
               FormatTwoDigits(tangent_error);
    } else if (tangent_decides && tangent_error > check.tolerance && verdict == CheckVerdict::kUnresolved &&
               IsDirectNewton(options.method)) {
      verdict = CheckVerdict::kFail;
      basis = "tangent";
      reason = "differs from the forward-mode tangent by " + FormatTwoDigits(tangent_error) + " relative (tolerance " +
               FormatTwoDigits(check.tolerance) + "); differences unresolved: " + reason;
    } else if (tangent_decides && tangent_error > check.tolerance) {
      reason += (reason.empty() ? "" : "; ") + std::string("differs from the forward-mode tangent by ") +
                FormatTwoDigits(tangent_error);
    }
    if (result.reference) {
      const double ref_error = RelativeDifference(analytic, reference_value);
      entry->reference_error = std::max(entry->reference_error, ref_error);
      if (!(ref_error <= check.tolerance) && basis == "tangent") {
        // The differences did not decide: the gradient is the adjoint of the
        // method's own (inexact) trajectory, which the tangent confirms.
        reason += "; differs from the Newton-Cholesky reference by " + FormatTwoDigits(ref_error) +
                  " (the method's trajectory is not the converged one)";
      } else if (!(ref_error <= check.tolerance) && verdict != CheckVerdict::kUnresolved) {
        // The differences decided. Where they pass decisively the gradient
        // is the derivative of the method's own loss: the disagreement is
        // the adjoint's only if it persists at a tighter forward tolerance.
        double tight_error = std::numeric_limits<double>::quiet_NaN();
        if (verdict == CheckVerdict::kPass && basis == "differences" && j.margin >= decisive)
          if (const std::optional<RolloutGradient>& t = tightened_gradient()) {
            tight_error = RelativeDifference(along(*t), reference_value);
            entry->tightened_reference_error =
                std::fmax(entry->tightened_reference_error, tight_error);  // NaN: none yet
          }
        if (tight_error <= check.tolerance && tight_error < ref_error) {
          margin = std::min(margin,
                            tight_error > 0 ? check.tolerance / tight_error : std::numeric_limits<double>::infinity());
          reason = "differs from the Newton-Cholesky reference by " + FormatTwoDigits(ref_error) + ", and by " +
                   FormatTwoDigits(tight_error) + " at rel_tolerance " + FormatTwoDigits(tightened_rel_tolerance) +
                   " (the forward's tolerance, not the adjoint)";
        } else {
          verdict = CheckVerdict::kFail;
          reason = "differs from the Newton-Cholesky reference by " + FormatTwoDigits(ref_error) +
                   " relative (tolerance " + FormatTwoDigits(check.tolerance) + ")" +
                   (std::isnan(tight_error) ? ""
                                            : ", and by " + FormatTwoDigits(tight_error) + " at rel_tolerance " +
                                                  FormatTwoDigits(tightened_rel_tolerance)) +
                   (reason.empty() ? "" : "; differences: " + reason);
        }
      } else if (!(ref_error <= check.tolerance)) {
        // The differences are unresolved (the forward's noise, or its
        // residuals' worst case, covers the disagreement): the method's
        // gradient is that of its inexact trajectory and cannot be held to
        // the converged one's either.
        reason += "; differs from the Newton-Cholesky reference by " + FormatTwoDigits(ref_error) +
                  ", within the forward's noise";
      } else if (verdict == CheckVerdict::kUnresolved) {
        reason += "; agrees with the Newton-Cholesky reference to " + FormatTwoDigits(ref_error);
      }
    }
    const bool first = entry->directions == 0;
    const bool strictly_worse = verdict != entry->verdict && Worse(verdict, entry->verdict) == verdict;
    if (first || strictly_worse || (verdict == entry->verdict && margin < entry->margin)) {
      entry->step = j.step;
      entry->reason = reason;
      entry->basis = basis;
    }
    ++entry->directions;
    // error, floor and bound: over the directions the differences decided,
    // or over all where the tangent decided every one.
    const bool by_tangent = basis == "tangent";
    entry->tangent_directions += by_tangent;
    entry->extrapolated_directions += !by_tangent && j.extrapolated;
    const int by_differences = entry->directions - entry->tangent_directions;
    if (!by_tangent && by_differences == 1) {
      entry->error = j.error;
      entry->floor = j.floor;
      entry->bound = j.bound;
    } else if (!by_tangent || by_differences == 0) {
      entry->error = std::max(entry->error, j.error);
      entry->floor = std::max(entry->floor, j.floor);
      entry->bound = std::max(entry->bound, j.bound);
    }
    entry->verdict = first ? verdict : Worse(entry->verdict, verdict);
    entry->margin = std::min(entry->margin, margin);
    if (check.progress)
      check.progress({name, entry->directions, directions, verdict, margin, basis, result.perturbed_rollouts});
  };

  for (int k = 0; k < check.directions; ++k) {
    const VectorXd dx = size * Direction(&rng, n);
    auto along_x = [&](const RolloutGradient& g) { return g.x0.dot(dx); };
    InputDirection along_x0;
    along_x0.x0 = dx;
    record("x0", n, check.directions, along_x, tangent_of(along_x0), [&](Simulator& worker, double e) {
      State s = initial;
      s.x += e * dx;
      return rollout_loss(worker, s, inputs);
    });
    const VectorXd dv = (size / h) * Direction(&rng, n);
    auto along_v = [&](const RolloutGradient& g) { return g.v0.dot(dv); };
    InputDirection along_v0;
    along_v0.v0 = dv;
    record("v0", n, check.directions, along_v, tangent_of(along_v0), [&](Simulator& worker, double e) {
      State s = initial;
      s.v += e * dv;
      return rollout_loss(worker, s, inputs);
    });
    // A force that moves a node by about `size` in one step: m size / h^2.
    std::vector<VectorXd> df(steps);
    for (int i = 0; i < steps; ++i)
      df[i] = (size / (h * h)) * mass.cwiseProduct(Direction(&rng, n)) / std::sqrt(double(steps));
    auto along_f = [&](const RolloutGradient& g) {
      double sum = 0;
      for (int i = 0; i < steps; ++i) sum += g.external_force[i].dot(df[i]);
      return sum;
    };
    InputDirection along_forces;
    along_forces.external_force = df;
    record("external_force", long(n) * steps, check.directions, along_f, tangent_of(along_forces),
           [&](Simulator& worker, double e) {
             std::vector<StepInput> in = inputs;
             for (int i = 0; i < steps; ++i) in[i].external_force += e * df[i];
             return rollout_loss(worker, initial, in);
           });
    if (num_muscles > 0) {
      std::vector<VectorXd> da(steps);
      for (int i = 0; i < steps; ++i) da[i] = Direction(&rng, num_muscles) / std::sqrt(double(steps));
      auto along_a = [&](const RolloutGradient& g) {
        double sum = 0;
        for (int i = 0; i < steps; ++i) sum += g.activation[i].dot(da[i]);
        return sum;
      };
      InputDirection along_activations;
      along_activations.activation = da;
      record("activation", long(num_muscles) * steps, check.directions, along_a, tangent_of(along_activations),
             [&](Simulator& worker, double e) {
               std::vector<StepInput> in = inputs;
               for (int i = 0; i < steps; ++i) in[i].activation += e * da[i];
               return rollout_loss(worker, initial, in);
             });
    }
  }

  // Scalar parameters: one direction each (the directions above only repeat them).
  // State-force parameters: a fresh simulator per perturbed scene.
  // `unit`: the parameter's unit direction (for the tangent).
  auto record_scene = [&](const std::string& name, double scale,
                          const std::function<double(const RolloutGradient&)>& derivative,
                          const std::function<void(Scene*, double)>& perturb, const InputDirection& unit) {
    record(
        name, 1, 1, [&](const RolloutGradient& g) { return scale * derivative(g); }, scale * tangent_of(unit),
        [&](Simulator&, double e) {
          Scene p = scene;
          perturb(&p, e * scale);
          Simulator s(p, perturbed_options);
          return rollout_loss(s, initial, inputs);
        });
  };
  auto unit_scale = [](double value) { return std::max(1.0, std::abs(value)); };
  auto unit_force = [](const std::function<void(StateForceGradient*)>& set) {
    InputDirection d;
    set(&d.state_forces);
    return d;
  };
  if (scene.linear_damping)
    record_scene(
        "linear_damping", unit_scale(*scene.linear_damping),
        [](const RolloutGradient& g) { return g.state_forces.linear_damping; },
        [](Scene* p, double e) { *p->linear_damping += e; },
        unit_force([](StateForceGradient* f) { f->linear_damping = 1; }));
  if (scene.hydrodynamics) {
    const Hydrodynamics& hy = *scene.hydrodynamics;
    record_scene(
        "fluid_density", unit_scale(hy.fluid_density),
        [](const RolloutGradient& g) { return g.state_forces.fluid_density; },
        [](Scene* p, double e) { p->hydrodynamics->fluid_density += e; },
        unit_force([](StateForceGradient* f) { f->fluid_density = 1; }));
    record_scene(
        "drag_tangential", unit_scale(hy.drag_tangential),
        [](const RolloutGradient& g) { return g.state_forces.drag_tangential; },
        [](Scene* p, double e) { p->hydrodynamics->drag_tangential += e; },
        unit_force([](StateForceGradient* f) { f->drag_tangential = 1; }));
    record_scene(
        "drag_normal", unit_scale(hy.drag_normal), [](const RolloutGradient& g) { return g.state_forces.drag_normal; },
        [](Scene* p, double e) { p->hydrodynamics->drag_normal += e; },
        unit_force([](StateForceGradient* f) { f->drag_normal = 1; }));
    record_scene(
        "thrust", unit_scale(hy.thrust), [](const RolloutGradient& g) { return g.state_forces.thrust; },
        [](Scene* p, double e) { p->hydrodynamics->thrust += e; },
        unit_force([](StateForceGradient* f) { f->thrust = 1; }));
  }
  bool any_friction = false;
  for (const auto& c : scene.penalty_contacts) any_friction = any_friction || c.friction > 0;
  if (any_friction) {
    // mu is at most 1 or so: a step of 1e-2 mu scale would cross stick/slip
    // thresholds; the friction coefficients move by e x 1.
    record_scene(
        "penalty_friction", 1.0,
        [&](const RolloutGradient& g) {
          double sum = 0;
          for (size_t c = 0; c < scene.penalty_contacts.size(); ++c)
            if (scene.penalty_contacts[c].friction > 0) sum += g.state_forces.penalty_friction[c];
          return sum;
        },
        [](Scene* p, double e) {
          for (auto& c : p->penalty_contacts)
            if (c.friction > 0) c.friction += e;
        },
        unit_force([&](StateForceGradient* f) {
          f->penalty_friction.assign(scene.penalty_contacts.size(), 0.0);
          for (size_t c = 0; c < scene.penalty_contacts.size(); ++c)
            if (scene.penalty_contacts[c].friction > 0) f->penalty_friction[c] = 1;
        }));
  }
  const MaterialParameters material = scene.material;
  auto record_material =
      [&](const std::string& name, double scale, const std::function<double(const RolloutGradient&)>& derivative,
          const std::function<void(MaterialParameters*, double)>& perturb, const InputDirection& unit) {
        record(
            name, 1, 1, [&](const RolloutGradient& g) { return scale * derivative(g); }, scale * tangent_of(unit),
            [&](Simulator& worker, double e) {
              MaterialParameters m = material;
              perturb(&m, e * scale);
              worker.SetMaterial(m);
              double l = 0;
              try {
                l = rollout_loss(worker, initial, inputs);
              } catch (...) {
                worker.SetMaterial(material);
                throw;
              }
              worker.SetMaterial(material);
              return l;
            });
      };
  record_material(
      "youngs_modulus", material.youngs_modulus, [](const RolloutGradient& g) { return g.youngs_modulus; },
      [](MaterialParameters* m, double e) { m->youngs_modulus += e; }, InputDirection::YoungsModulus());
  // Keep nu + e scale inside (-1, 0.5) for e <= 1 (the widened steps reach 0.3).
  record_material(
      "poissons_ratio", std::min(0.1, 0.5 * (0.5 - material.poissons_ratio)),
      [](const RolloutGradient& g) { return g.poissons_ratio; },
      [](MaterialParameters* m, double e) { m->poissons_ratio += e; }, InputDirection::PoissonsRatio());
  record_material(
      "density", material.density, [](const RolloutGradient& g) { return g.density; },
      [](MaterialParameters* m, double e) { m->density += e; }, InputDirection::Density());

  result.min_margin = std::numeric_limits<double>::infinity();
  for (const auto& e : result.inputs) {
    result.verdict = Worse(result.verdict, e.verdict);
    result.max_error = std::max(result.max_error, e.error);
    result.min_margin = std::min(result.min_margin, e.margin);
  }
  return result;
}

GradCheckResult CheckRolloutGradientAtReachableTolerance(const Scene& scene, const SolverOptions& options,
                                                         const State& initial, int steps, const GradCheckOptions& check,
                                                         double loosest_rel_tolerance, double* used_rel_tolerance) {
  SolverOptions o = options;
  for (;;) {
    try {
      GradCheckResult r = CheckRolloutGradient(scene, o, initial, steps, check);
      if (used_rel_tolerance) *used_rel_tolerance = o.rel_tolerance;
      return r;
    } catch (const SolverError& e) {
      // 1.001: the products of 100 carry rounding.
      if (e.status() != SolverStatus::kMaxIterations || o.rel_tolerance * 100 > 1.001 * loosest_rel_tolerance) throw;
      o.rel_tolerance *= 100;
    }
  }
}

std::string GradCheckTable(const GradCheckResult& r) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "%-16s %10s %10s %10s %9s %10s %10s %10s %-11s %-11s %s\n", "input", "error",
                "floor", "margin", "step", "worst_case", "reference", "tangent", "verdict", "basis", "reason");
  out += line;
  for (const auto& e : r.inputs) {
    char ref[32], tangent[32];
    auto cell = [](char* out, double v) {
      if (std::isnan(v))
        std::snprintf(out, 32, "%10s", "-");
      else
        std::snprintf(out, 32, "%10.2e", v);
    };
    cell(ref, e.reference_error);
    cell(tangent, e.tangent_error);
    // Where the tangent decided some directions but not all: how many.
    std::string basis = e.tangent_directions > 0 && e.tangent_directions < e.directions
                            ? e.basis + " (" + std::to_string(e.tangent_directions) + "/" +
                                  std::to_string(e.directions) + " by tangent)"
                            : e.basis;
    if (e.extrapolated_directions > 0)
      basis += " (" + std::to_string(e.extrapolated_directions) + "/" + std::to_string(e.directions) + " extrapolated)";
    std::snprintf(line, sizeof(line), "%-16s %10.2e %10.2e %10.3g %9.0e %10.2e %s %s %-11s %-11s %s\n", e.input.c_str(),
                  e.error, e.floor, e.margin, e.step, e.bound, ref, tangent, ToString(e.verdict), basis.c_str(),
                  e.reason.c_str());
    out += line;
  }
  std::snprintf(line, sizeof(line),
                "# %s: %s (tolerance %g; %d pass, %d fail, %d unresolved; smallest margin %.3g; %ld perturbed "
                "rollouts)%s\n",
                r.method.c_str(), ToString(r.verdict), r.tolerance, r.Count(CheckVerdict::kPass),
                r.Count(CheckVerdict::kFail), r.Count(CheckVerdict::kUnresolved), r.min_margin, r.perturbed_rollouts,
                r.reference ? "; reference: newton-cholesky" : "");
  out += line;
  if (!r.reference_failure.empty()) out += "# the Newton-Cholesky reference failed: " + r.reference_failure + "\n";
  if (r.time_step > r.explicit_stable_time_step) {
    std::snprintf(line, sizeof(line),
                  "# unstable: h = %g s is %.3g x semi-implicit Euler's stability limit at the initial state (%.3g s): "
                  "the rollout grows without bound and the gradient is that of a diverging trajectory\n",
                  r.time_step, r.time_step / r.explicit_stable_time_step, r.explicit_stable_time_step);
    out += line;
  }
  return out;
}

nlohmann::json GradCheckToJson(const GradCheckResult& r) {
  // JSON has no NaN or infinity: null stands for "not compared" / "exact".
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json inputs = nlohmann::json::object();
  for (const auto& e : r.inputs)
    inputs[e.input] = {{"verdict", ToString(e.verdict)},
                       {"error", number(e.error)},
                       {"floor", number(e.floor)},
                       {"worst_case", number(e.bound)},
                       {"margin", number(e.margin)},
                       {"step", e.step},
                       {"reference_error", number(e.reference_error)},
                       {"tightened_reference_error", number(e.tightened_reference_error)},
                       {"tangent_error", number(e.tangent_error)},
                       {"basis", e.basis},
                       {"tangent_directions", e.tangent_directions},
                       {"extrapolated_directions", e.extrapolated_directions},
                       {"reason", e.reason},
                       {"entries", e.entries},
                       {"directions", e.directions}};
  return {{"method", r.method},
          {"tolerance", r.tolerance},
          {"verdict", ToString(r.verdict)},
          {"max_error", number(r.max_error)},
          {"min_margin", number(r.min_margin)},
          {"reference", r.reference},
          {"tangent", r.tangent},
          {"reference_failure", r.reference_failure},
          {"pass", r.Count(CheckVerdict::kPass)},
          {"fail", r.Count(CheckVerdict::kFail)},
          {"unresolved", r.Count(CheckVerdict::kUnresolved)},
          {"perturbed_rollouts", r.perturbed_rollouts},
          {"explicit_stable_time_step", number(r.explicit_stable_time_step)},
          {"inputs", inputs}};
}

}  // namespace diffpd::problems
