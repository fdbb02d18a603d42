#include "tools/optimiser_tradeoff.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "diffpd/error.h"
#include "tools/tradeoff.h"

namespace diffpd::problems {
namespace {

nlohmann::json Number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

}  // namespace

OptimiserTradeoff RunOptimiserTradeoff(const ProblemObjective& objective, const std::vector<double>& tolerances,
                                       const OptimiserTradeoffOptions& options, std::ostream* progress) {
  if (!objective.optimise)
    throw InvalidInputError("problem '" + objective.problem +
                            "' has no optimiser of its own (a forward scene): the optimiser trade-off needs an "
                            "optimisation, calibration or control problem");
  if (tolerances.empty()) throw InvalidInputError("tolerances is empty: give at least one relative tolerance");
  for (double t : tolerances)
    if (!(t > 0 && t < 1)) {
      std::ostringstream msg;
      msg << "tolerance = " << t << " is invalid: must be in (0, 1)";
      throw InvalidInputError(msg.str());
    }
  OptimiserTradeoff result;
  result.problem = objective.problem;
  result.optimiser = objective.optimiser;
  result.loss = objective.loss;
  result.method = ToString(objective.defaults.method);
  result.default_rel_tolerance = objective.defaults.rel_tolerance;
  result.dofs = objective.dofs;
  result.steps = objective.steps;
  // The default's tolerance is always measured; loose to tight.
  std::vector<double> sweep = tolerances;
  if (std::find(sweep.begin(), sweep.end(), result.default_rel_tolerance) == sweep.end())
    sweep.push_back(result.default_rel_tolerance);
  std::sort(sweep.begin(), sweep.end(), std::greater<double>());
  for (double tolerance : sweep) {
    SolverOptions o = objective.defaults;
    o.rel_tolerance = tolerance;
    if (progress)
      *progress << "[optimiser tradeoff] " << objective.problem << ": " << result.method << " at rel_tolerance "
                << tolerance << " ..." << std::endl;
    OptimiserTradeoffRow row;
    row.rel_tolerance = tolerance;
    row.outcome = objective.optimise(o, options.max_iterations);
    if (progress) {
      if (row.outcome.ok())
        *progress << "[optimiser tradeoff]   " << row.outcome.wall_s << " s, " << row.outcome.evaluations
                  << " evaluations, final loss " << row.outcome.final_loss << " (" << row.outcome.status << ")"
                  << std::endl;
      else
        *progress << "[optimiser tradeoff]   failed: " << row.outcome.failure << std::endl;
    }
    result.rows.push_back(row);
  }
  // Shortfall against the best run.
  double best = std::numeric_limits<double>::infinity(), initial = std::numeric_limits<double>::quiet_NaN();
  for (const auto& r : result.rows)
    if (r.outcome.ok() && std::isfinite(r.outcome.final_loss)) {
      best = std::min(best, r.outcome.final_loss);
      initial = r.outcome.initial_loss;  // the same start for every run
    }
  const double improvement = initial - best;
  for (auto& r : result.rows)
    r.shortfall = r.outcome.ok() && improvement > 0 ? (r.outcome.final_loss - best) / improvement
                                                    : std::numeric_limits<double>::quiet_NaN();
  return result;
}

nlohmann::json OptimiserTradeoffJson(const OptimiserTradeoff& t) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : t.rows) {
    const OptimiserOutcome& o = r.outcome;
    rows.push_back({{"rel_tolerance", r.rel_tolerance},
                    {"status", o.ok() ? o.status : "failed: " + o.failure},
                    {"wall_s", o.ok() ? Number(o.wall_s) : nullptr},
                    {"evaluations", o.evaluations},
                    {"iterations", o.iterations},
                    {"initial_loss", o.ok() ? Number(o.initial_loss) : nullptr},
                    {"final_loss", o.ok() ? Number(o.final_loss) : nullptr},
                    {"reported_loss", o.ok() ? Number(o.reported_loss) : nullptr},
                    {"constraint_violation", o.ok() ? Number(o.constraint_violation) : nullptr},
                    {"shortfall", Number(r.shortfall)}});
  }
  return {{"problem", t.problem},
          {"optimiser", t.optimiser},
          {"loss", t.loss + " (re-evaluated with newton-cholesky at rel_tolerance 1e-10)"},
          {"method", t.method},
          {"default_rel_tolerance", t.default_rel_tolerance},
          {"dofs", t.dofs},
          {"steps", t.steps},
          {"runs", rows}};
}

OptimiserTradeoff OptimiserTradeoffFromJson(const nlohmann::json& j) {
  auto number = [](const nlohmann::json& v) {
    return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
  };
  try {
    OptimiserTradeoff t;
    t.problem = j.at("problem").get<std::string>();
    t.optimiser = j.at("optimiser").get<std::string>();
    t.loss = j.at("loss").get<std::string>();
    t.method = j.at("method").get<std::string>();
    t.default_rel_tolerance = j.at("default_rel_tolerance").get<double>();
    t.dofs = j.at("dofs").get<int>();
    t.steps = j.at("steps").get<int>();
    for (const auto& r : j.at("runs")) {
      OptimiserTradeoffRow row;
      row.rel_tolerance = r.at("rel_tolerance").get<double>();
      const std::string status = r.at("status").get<std::string>();
      if (r.at("wall_s").is_null() && status.rfind("failed: ", 0) == 0) {
        row.outcome.failure = status.substr(8);
      } else {
        row.outcome.status = status;
        row.outcome.wall_s = number(r.at("wall_s"));
        row.outcome.initial_loss = number(r.at("initial_loss"));
        row.outcome.final_loss = number(r.at("final_loss"));
        row.outcome.reported_loss = number(r.at("reported_loss"));
        row.outcome.constraint_violation = number(r.at("constraint_violation"));
      }
      row.outcome.evaluations = r.at("evaluations").get<long>();
      row.outcome.iterations = r.at("iterations").get<int>();
      row.shortfall = number(r.at("shortfall"));
      t.rows.push_back(row);
    }
    return t;
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInputError(std::string("optimiser trade-off report: ") + e.what());
  }
}

void WriteOptimiserTradeoffPlot(const OptimiserTradeoff& t, const std::string& png_path) {
  if (!GnuplotAvailable())
    throw std::runtime_error(
        "the optimiser trade-off plot needs the gnuplot program, which is not on PATH (Debian: apt-get install "
        "gnuplot-nox)");
  constexpr double kZero = 1e-16;  // where a shortfall of 0 is drawn
  std::ostringstream data, marked;
  data.precision(17);
  marked.precision(17);
  int n = 0;
  for (const auto& r : t.rows) {
    if (!r.outcome.ok() || !std::isfinite(r.shortfall)) continue;
    std::ostringstream line;
    line.precision(17);
    std::ostringstream label;  // default precision: 1e-04, 0.01
    label << r.rel_tolerance;
    line << r.outcome.wall_s << " " << std::max(r.shortfall, kZero) << " \"" << label.str() << "\"\n";
    data << line.str();
    if (r.rel_tolerance == t.default_rel_tolerance) marked << line.str();
    ++n;
  }
  if (n == 0) throw std::runtime_error("nothing to plot: no optimiser run improved on the start");
  std::ostringstream script;
  script << "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size 800,550 } else { set "
            "terminal png size 800,550 }\n";
  script << "set output " << GnuplotQuote(png_path) << "\n";
  script << "set logscale xy\nset format y '10^{%L}'\nset grid\nset key below\n";
  script << "set title " << GnuplotQuote("diffpd tradeoff --optimiser: " + t.problem + " (" + t.method + ")") << "\n";
  script << "set xlabel 'wall time of the whole optimisation (s)'\n";
  script << "set ylabel " << GnuplotQuote("shortfall of the converged final loss (0 drawn at 1e-16)") << "\n";
  script << "$runs << EOD\n" << data.str() << "EOD\n";
  script << "$default << EOD\n" << marked.str() << "EOD\n";
  script << "plot $runs using 1:2 with points pt 7 ps 1.5 title 'one run per rel\\_tolerance (labelled)', "
            "$runs using 1:2:3 with labels offset 0,1 font ',9' notitle";
  if (!marked.str().empty()) script << ", $default using 1:2 with points pt 6 ps 3 lw 2 title 'default'";
  script << "\n";
  RunGnuplot(script.str(), png_path);
}

}  // namespace diffpd::problems
