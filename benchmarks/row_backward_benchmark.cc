// Benchmark (not a test): the backward pass of pd-lbfgs on the paper's Table
// rows at the paper's sizes, per adjoint setting, as `diffpd table` runs them.
//
// Per row: the row's preparatory simulations, then one simulator per
// setting (the row's own options, `PaperRow::Options(kPdLbfgs, threads)`,
// changed as the setting says) evaluating the loss and its gradient at
// x_init (the row's given initial guess; a row whose guess is the best
// random draw takes its first draw, no draws being run) --evaluations
// times, the settings interleaved so that a change of machine load hits
// them alike. Reported per setting: the medians of the forward and backward
// seconds, the forward and adjoint iterations per step, and the relative
// error of dL/dx (the row's variables) against the `direct` setting's (the
// exact adjoint of the same forward: what the adjoint's own tolerance
// costs, not the forward's; "nan" without a direct setting).
//
// Settings: row (the table's: auto adjoint at backward_rel_tolerance =
// rel_tolerance), iterative, direct, derived (iterative at
// backward_rel_tolerance = 0), no-guess (iterative, adjoint_guess_solutions
// = 0), guess-M (iterative, M guess solutions), scale-W (iterative,
// lbfgs_weight_scale W: the forward's and the adjoint's preconditioner).
//
// Usage: row_backward_benchmark [--rows plant,routing-tendon] [--threads 1]
//   [--evaluations 3] [--settings row,iterative,direct,...] [--clock wall|cpu]
//   [--masses equal-nodes|lumped] [--rtol R] [--json]
// --rtol: every setting's forward rel_tolerance, and its adjoint's where the
// row ties them (default: the row's own).
// --masses: the rows' masses, as `diffpd table --masses` (default: the
// original code's, equal-nodes).
// --clock cpu: the process's CPU seconds instead of wall seconds (steadier
// on a loaded machine with --threads 1; includes OpenMP's spinning with more).

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/simulator.h"
#include "paper/paper_rows.h"
#include "paper/row_evaluation.h"
#include "tools/bench.h"

namespace diffpd {
namespace {

using problems::PaperRow;
using problems::RowEvaluation;

struct Setting {
  std::string name;
  std::function<void(SolverOptions*)> change;
};

std::vector<Setting> AllSettings() {
  return {
      {"row", [](SolverOptions*) {}},
      {"iterative", [](SolverOptions* o) { o->adjoint_solver = AdjointSolver::kIterative; }},
      {"direct", [](SolverOptions* o) { o->adjoint_solver = AdjointSolver::kDirect; }},
      {"derived",
       [](SolverOptions* o) {
         o->adjoint_solver = AdjointSolver::kIterative;
         o->backward_rel_tolerance = 0;
       }},
      {"no-guess",
       [](SolverOptions* o) {
         o->adjoint_solver = AdjointSolver::kIterative;
         o->adjoint_guess_solutions = 0;
       }},
  };
}

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// EvaluateRow with the process's CPU seconds (--clock cpu: on a loaded
// machine a 1-thread run's CPU time is far steadier than its wall time) or
// wall seconds.
RowEvaluation Evaluate(const PaperRow& row, Simulator* sim, const VectorXd& x, bool cpu) {
  return problems::EvaluateRow(row, sim, x, true, cpu ? problems::RowClock::kCpu : problems::RowClock::kWall);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Result {
  std::string row, setting, failure;
  double forward_s = 0, backward_s = 0, forward_iterations = 0, backward_iterations = 0, gradient_error = 0;
  int fallbacks = 0;
};

int Main(int argc, char** argv) {
  std::vector<std::string> rows = {"plant", "routing-tendon"};
  std::vector<std::string> names;
  int threads = 1, evaluations = 3;
  bool json = false, cpu = false;
  double rel_tolerance = -1;                      // <= 0: the row's
  MassLumping masses = MassLumping::kEqualNodes;  // the table's default
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw InvalidInputError(a + " needs a value");
      return argv[++i];
    };
    if (a == "--rows") {
      rows = Split(next());
    } else if (a == "--threads") {
      threads = std::stoi(next());
    } else if (a == "--evaluations") {
      evaluations = std::stoi(next());
    } else if (a == "--settings") {
      names = Split(next());
    } else if (a == "--masses") {
      masses = ParseMassLumping(next());
    } else if (a == "--clock") {
      const std::string c = next();
      if (c != "cpu" && c != "wall") throw InvalidInputError("--clock " + c + " is invalid: must be cpu or wall");
      cpu = c == "cpu";
    } else if (a == "--rtol") {
      rel_tolerance = std::stod(next());
      if (!(rel_tolerance > 0 && rel_tolerance < 1))
        throw InvalidInputError("--rtol " + std::to_string(rel_tolerance) + " is invalid: must be in (0, 1)");
    } else if (a == "--json") {
      json = true;
    } else {
      throw InvalidInputError("unknown argument '" + a + "'");
    }
  }
  std::vector<Setting> settings;
  for (const Setting& s : AllSettings())
    if (names.empty() || std::find(names.begin(), names.end(), s.name) != names.end()) settings.push_back(s);
  for (const std::string& name : names)
    if (name.rfind("scale-", 0) == 0) {
      const double w = std::stod(name.substr(6));
      settings.push_back({name, [w](SolverOptions* o) {
                            o->adjoint_solver = AdjointSolver::kIterative;
                            o->lbfgs_weight_scale = w;
                          }});
    } else if (name.rfind("guess-", 0) == 0) {
      const int m = std::stoi(name.substr(6));
      settings.push_back({name, [m](SolverOptions* o) {
                            o->adjoint_solver = AdjointSolver::kIterative;
                            o->adjoint_guess_solutions = m;
                          }});
    }
  std::vector<Result> results;
  for (const std::string& name : rows) {
    PaperRow row = problems::MakePaperRow(name, problems::RowSize::kPaper);
    problems::SetRowMasses(&row, masses);
    row.Prepare(row.Options(Method::kPdLbfgs, threads));
    const VectorXd x = row.random_draws.empty() || row.initial_guess == problems::InitialGuess::kGiven
                           ? row.initial()
                           : row.random_draws.front();
    std::vector<std::unique_ptr<Simulator>> sims;
    for (const Setting& s : settings) {
      SolverOptions o = row.Options(Method::kPdLbfgs, threads);
      if (rel_tolerance > 0) {
        if (o.backward_rel_tolerance == o.rel_tolerance) o.backward_rel_tolerance = rel_tolerance;
        o.rel_tolerance = rel_tolerance;
      }
      s.change(&o);
      sims.push_back(std::make_unique<Simulator>(row.scene, o));
    }
    std::vector<std::vector<RowEvaluation>> runs(settings.size());
    for (int r = 0; r < evaluations; ++r)
      for (size_t c = 0; c < settings.size(); ++c) {
        runs[c].push_back(Evaluate(row, sims[c].get(), x, cpu));
        const RowEvaluation& e = runs[c].back();
        std::cerr << "[row-backward] " << name << " " << settings[c].name << " run " << r + 1 << ": " << e.forward_s
                  << " s + " << e.backward_s << " s, " << e.backward_iterations_per_step << " adjoint its/step, "
                  << e.backward_indefinite_steps << " steps with an indefinite Hessian, |dL/dx| " << e.gradient.norm()
                  << std::endl;
      }
    int reference = -1;  // no error without the direct setting
    for (size_t c = 0; c < settings.size(); ++c)
      if (settings[c].name == "direct") reference = static_cast<int>(c);
    for (size_t c = 0; c < settings.size(); ++c) {
      Result out;
      out.row = name;
      out.setting = settings[c].name;
      std::vector<double> fwd, bwd;
      for (const RowEvaluation& e : runs[c]) {
        fwd.push_back(e.forward_s);
        bwd.push_back(e.backward_s);
      }
      out.forward_s = Median(fwd);
      out.backward_s = Median(bwd);
      out.forward_iterations = runs[c].back().iterations_per_step;
      out.backward_iterations = runs[c].back().backward_iterations_per_step;
      out.fallbacks = runs[c].back().backward_fallbacks;
      out.gradient_error = reference < 0
                               ? std::numeric_limits<double>::quiet_NaN()
                               : problems::RelativeError(runs[c].back().gradient, runs[reference].back().gradient);
      results.push_back(out);
    }
  }
  if (json) {
    nlohmann::json j = nlohmann::json::array();
    for (const Result& r : results)
      j.push_back({{"row", r.row},
                   {"setting", r.setting},
                   {"threads", threads},
                   {"forward_s", r.forward_s},
                   {"backward_s", r.backward_s},
                   {"forward_iterations_per_step", r.forward_iterations},
                   {"adjoint_iterations_per_step", r.backward_iterations},
                   {"fallbacks", r.fallbacks},
                   {"gradient_error_vs_direct", r.gradient_error}});
    std::cout << j.dump(2) << std::endl;
    return 0;
  }
  std::printf(
      "| row | setting | fwd s | bwd s | bwd / fwd | iterations/step (fwd, adjoint) | dL/dx error vs direct |\n");
  std::printf("|---|---|---:|---:|---:|---|---:|\n");
  for (const Result& r : results)
    std::printf("| %s | %s | %.3g | %.3g | %.2f | %.1f, %.1f | %.1e |\n", r.row.c_str(), r.setting.c_str(), r.forward_s,
                r.backward_s, r.backward_s / r.forward_s, r.forward_iterations, r.backward_iterations,
                r.gradient_error);
  return 0;
}

}  // namespace
}  // namespace diffpd

int main(int argc, char** argv) {
  try {
    return diffpd::Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "row_backward_benchmark: " << e.what() << std::endl;
    return 1;
  }
}
