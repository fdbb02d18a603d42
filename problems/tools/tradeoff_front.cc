#include "tools/tradeoff_front.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

double ErrorOf(const TradeoffRow& r, int which) {
  return which == 0 ? r.state_rel_error : which == 1 ? r.loss_rel_error : r.grad_rel_error;
}

// The tolerance sweep of `method`, tightest last.
std::vector<const TradeoffRow*> SweepOf(const std::vector<TradeoffRow>& rows, const std::string& method) {
  std::vector<const TradeoffRow*> out;
  for (const auto& r : rows)
    if (r.sweep == "tolerance" && r.method == method) out.push_back(&r);
  std::sort(out.begin(), out.end(), [](const TradeoffRow* a, const TradeoffRow* b) { return a->value > b->value; });
  return out;
}

// The loosest tolerance t of the sweep such that every run at t or tighter
// succeeded with gradient error <= bound (0: none); its row in *row.
double LoosestMeeting(const std::vector<const TradeoffRow*>& sweep, double bound, const TradeoffRow** row) {
  double loosest = 0;
  *row = nullptr;
  for (auto it = sweep.rbegin(); it != sweep.rend(); ++it) {
    if (!(*it)->ok() || (*it)->grad_rel_error > bound) break;
    loosest = (*it)->value;
    *row = *it;
  }
  return loosest;
}

}  // namespace

std::vector<MonotonicityViolation> CheckMonotone(const std::vector<TradeoffRow>& rows, double noise_factor,
                                                 double floor) {
  std::vector<std::string> methods;
  for (const auto& r : rows)
    if (r.sweep == "tolerance" && std::find(methods.begin(), methods.end(), r.method) == methods.end())
      methods.push_back(r.method);
  const char* names[3] = {"state", "loss", "gradient"};
  std::vector<MonotonicityViolation> out;
  for (const auto& m : methods) {
    const auto sweep = SweepOf(rows, m);
    for (size_t i = 0; i < sweep.size(); ++i)
      for (size_t j = i + 1; j < sweep.size(); ++j) {
        if (!sweep[i]->ok() || !sweep[j]->ok()) continue;
        for (int w = 0; w < 3; ++w) {
          const double loose = ErrorOf(*sweep[i], w), tight = ErrorOf(*sweep[j], w);
          if (tight > noise_factor * loose + floor)
            out.push_back({m, names[w], sweep[i]->value, sweep[j]->value, loose, tight});
        }
      }
  }
  return out;
}

TradeoffFront AnalyseFront(const TradeoffResult& result) {
  const auto& rows = result.rows;
  if (rows.empty() || rows[0].sweep != "default")
    throw InvalidInputError("AnalyseFront: rows[0] must be the default run");
  TradeoffFront f;
  for (size_t i = 0; i < rows.size(); ++i) {
    const TradeoffRow& a = rows[i];
    if (!a.ok() || !a.at_problem_settings()) continue;
    bool dominated = false;
    for (const auto& b : rows)
      if (&b != &a && b.ok() && b.at_problem_settings() && b.seconds <= a.seconds &&
          b.grad_rel_error <= a.grad_rel_error && (b.seconds < a.seconds || b.grad_rel_error < a.grad_rel_error)) {
        dominated = true;
        break;
      }
    if (!dominated) f.front.push_back(static_cast<int>(i));
  }
  const TradeoffRow& d = rows[0];
  if (d.ok()) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& r : rows)
      if (r.ok() && r.at_problem_settings() && r.grad_rel_error <= d.grad_rel_error) best = std::min(best, r.seconds);
    f.default_seconds = d.seconds;
    for (const auto& r : rows)
      if (r.ok() && r.default_settings) f.default_seconds = std::min(f.default_seconds, r.seconds);
    f.default_slowdown = f.default_seconds / best;
    f.default_on_front = f.default_slowdown <= 1.1;
  }
  // The default method's sweep with the default run itself where its
  // tolerance was not swept (a default between the swept decades).
  auto default_sweep = SweepOf(rows, result.default_method);
  if (std::none_of(default_sweep.begin(), default_sweep.end(),
                   [&](const TradeoffRow* r) { return r->value == d.value; })) {
    default_sweep.push_back(&d);
    std::sort(default_sweep.begin(), default_sweep.end(),
              [](const TradeoffRow* a, const TradeoffRow* b) { return a->value > b->value; });
  }
  const auto lbfgs_sweep = SweepOf(rows, ToString(Method::kPdLbfgs));
  for (double bound : {1e-3, 1e-2, 1e-1}) {
    ErrorBound b;
    b.bound = bound;
    double best = std::numeric_limits<double>::infinity(), best_newton = best;
    for (const auto& r : rows) {
      if (!r.ok() || !r.at_problem_settings() || r.grad_rel_error > bound) continue;
      if (r.seconds < best) {
        best = r.seconds;
        b.met = true;
        b.method = r.method;
        b.setting = r.sweep + (r.setting.empty() ? "" : " " + r.setting);
        b.rel_tolerance = r.rel_tolerance;
        b.seconds = r.seconds;
        b.grad_rel_error = r.grad_rel_error;
      }
      if (r.method.rfind("newton", 0) == 0) best_newton = std::min(best_newton, r.seconds);
    }
    if (std::isfinite(best_newton)) b.best_newton_seconds = best_newton;
    const TradeoffRow* row = nullptr;
    b.default_method_tolerance = LoosestMeeting(default_sweep, bound, &row);
    if (b.default_method_tolerance > 0) b.loosening = b.default_method_tolerance / result.default_rel_tolerance;
    b.pd_lbfgs_tolerance = LoosestMeeting(lbfgs_sweep, bound, &row);
    if (row) b.pd_lbfgs_seconds = row->seconds;
    f.bounds.push_back(b);
  }
  return f;
}

nlohmann::json TradeoffReportJson(const TradeoffResult& result, const TradeoffFront& front,
                                  const std::vector<MonotonicityViolation>& violations) {
  const TradeoffRow& d = result.rows.at(0);
  nlohmann::json bounds = nlohmann::json::array(), bad = nlohmann::json::array();
  for (const auto& b : front.bounds)
    bounds.push_back({{"grad_rel_error_bound", b.bound},
                      {"met", b.met},
                      {"fastest_method", b.method},
                      {"fastest_setting", b.setting},
                      {"fastest_rel_tolerance", b.rel_tolerance},
                      {"fastest_seconds", b.seconds},
                      {"default_method_loosest_tolerance", b.default_method_tolerance},
                      {"loosening_over_default", b.loosening},
                      {"pd_lbfgs_loosest_tolerance", b.pd_lbfgs_tolerance},
                      {"pd_lbfgs_seconds", b.pd_lbfgs_seconds},
                      {"best_newton_seconds", b.best_newton_seconds}});
  for (const auto& v : violations)
    bad.push_back({{"method", v.method},
                   {"error", v.error},
                   {"looser_tolerance", v.looser_tolerance},
                   {"tighter_tolerance", v.tighter_tolerance},
                   {"looser_error", v.looser_error},
                   {"tighter_error", v.tighter_error}});
  return {{"problem", result.problem},
          {"variables", result.variables},
          {"loss", result.loss},
          {"dofs", result.dofs},
          {"steps", result.steps},
          {"time_step", result.time_step},
          {"masses", result.masses},
          {"reference_seconds", result.reference_s},
          {"reference_cached", result.reference_cached},
          {"repeats", result.repeats},
          {"clock", result.clock == TradeoffClock::kCpu ? "cpu" : "wall"},
          {"default",
           {{"method", result.default_method},
            {"rel_tolerance", result.default_rel_tolerance},
            {"seconds", d.seconds},
            {"seconds_fastest_at_its_settings", front.default_seconds},
            {"grad_rel_error", d.grad_rel_error},
            {"status", d.ok() ? std::string("ok") : "failed: " + d.failure},
            {"slowdown_over_front", front.default_slowdown},
            {"on_front_within_10_percent", front.default_on_front}}},
          {"front", front.front},
          {"bounds", bounds},
          {"monotonicity_violations", bad},
          {"rows", TradeoffToJson(result.rows)}};
}

}  // namespace diffpd::problems
