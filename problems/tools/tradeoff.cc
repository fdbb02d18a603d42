#include "tools/tradeoff.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "tools/bench.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "cli/invalid_option.h"

namespace diffpd::problems {
namespace {

SolverOptions Options(Method method, double tolerance, double h, int threads, int max_iterations) {
  SolverOptions s;
  s.max_iterations = max_iterations;
  s.method = method;
  s.time_step = h;
  s.rel_tolerance = tolerance;
  s.backward_rel_tolerance = tolerance;
  s.num_threads = threads;
  return s;
}

SolverOptions ReferenceOptions(double h, int threads) {
  SolverOptions s = Options(Method::kNewtonCholesky, kReferenceRelTolerance, h, threads, 1000);
  s.backward_rel_tolerance = kReferenceBackwardRelTolerance;
  return s;
}

void Progress(std::ostream* out, const std::string& line) {
  if (out) *out << line << std::endl;
}

RolloutMeasurement MustSucceed(RolloutMeasurement m, const std::string& what) {
  if (!m.ok())
    throw SolverError(m.status,
                      "the reference (" + what + ", newton-cholesky, rel_tolerance 1e-10) failed: " + m.failure);
  return m;
}

TradeoffRow MakeRow(const std::string& sweep, Method method, const std::string& parameter, double value,
                    const RolloutMeasurement& m, int dofs, int steps) {
  TradeoffRow row;
  row.sweep = sweep;
  row.method = ToString(method);
  row.parameter = parameter;
  row.value = value;
  row.failure = m.failure;
  row.dofs = dofs;
  row.steps = steps;
  if (m.ok()) {
    row.forward_s = m.forward_s;
    row.backward_s = m.backward_s;
    row.seconds = m.forward_s + m.backward_s;
    row.iters_per_step = m.iters_per_step;
  }
  return row;
}

std::string Describe(const TradeoffRow& r) {
  std::ostringstream s;
  s << "[tradeoff] " << r.sweep << " " << r.method << " " << r.parameter << " = " << r.value << ": ";
  if (!r.failure.empty())
    s << "failed: " << r.failure;
  else
    s << r.seconds << " s, state error " << r.state_rel_error << ", gradient error " << r.grad_rel_error;
  return s.str();
}

// The DoFs of the 8 nodes nearest the corners of the rest bounding box.
std::vector<int> CornerDofs(const Mesh& mesh) {
  const Vec3 lo = mesh.vertices.rowwise().minCoeff(), hi = mesh.vertices.rowwise().maxCoeff();
  std::vector<int> dofs;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    Eigen::Index best;
    (mesh.vertices.colwise() - corner).colwise().squaredNorm().minCoeff(&best);
    for (int d = 0; d < 3; ++d) dofs.push_back(3 * static_cast<int>(best) + d);
  }
  return dofs;
}

// A resolution level's corner displacements and scaled material gradient.
struct CornerMeasurement {
  RolloutMeasurement m;
  VectorXd displacement;       // 24
  VectorXd material_gradient;  // (E dL/dE, nu dL/dnu, rho dL/drho)
  int dofs = 0, steps = 0, elements = 0;
};

CornerMeasurement MeasureCorners(const std::string& problem_name, int doublings, const SolverOptions& so,
                                 int steps_option, const VectorXd& corner_weights) {
  const auto problem = MakeRefinedProblem(problem_name, doublings);
  const Scene scene = problem->MakeScene();
  const int steps = steps_option > 0 ? steps_option : problem->default_steps();
  Simulator sim(scene, so);
  const State initial = problem->InitialState(sim);
  const std::vector<int> corners = CornerDofs(scene.mesh);
  LinearLoss loss;
  loss.cx = VectorXd::Zero(sim.num_dofs());
  loss.cv = VectorXd::Zero(sim.num_dofs());
  for (size_t k = 0; k < corners.size(); ++k) loss.cx(corners[k]) = corner_weights(k);
  CornerMeasurement out;
  out.m = MeasureRollout(scene, so, initial, problem->Inputs(sim, steps), loss, 1);
  out.dofs = sim.num_dofs();
  out.steps = steps;
  out.elements = scene.mesh.num_elements();
  if (out.m.ok()) {
    const VectorXd rest = sim.RestState().x;
    out.displacement.resize(corners.size());
    for (size_t k = 0; k < corners.size(); ++k)
      out.displacement(k) = out.m.final_state.x(corners[k]) - rest(corners[k]);
    const int n = sim.num_dofs();
    const MaterialParameters& mat = scene.material;
    out.material_gradient =
        Eigen::Vector3d(mat.youngs_modulus * out.m.gradient(2 * n), mat.poissons_ratio * out.m.gradient(2 * n + 1),
                        mat.density * out.m.gradient(2 * n + 2));
  }
  return out;
}

}  // namespace

void TradeoffOptions::Validate() const {
  const auto fail = ThrowInvalidOption;
  if (methods.empty()) throw InvalidInputError("methods is empty: name at least one method");
  for (Method m : methods)
    if (m == Method::kSemiImplicit)
      throw InvalidInputError(
          "method semi-implicit has no tolerance to trade: use newton-cholesky, newton-pcg, "
          "pd or pd-lbfgs");
  if (sweep_tolerance && tolerances.empty()) throw InvalidInputError("tolerances is empty: give at least one");
  for (double t : tolerances)
    if (!(t > 0 && t < 1)) fail("tolerance", t, "in (0, 1)");
  if (!(rel_tolerance > 0 && rel_tolerance < 1)) fail("rtol", rel_tolerance, "in (0, 1)");
  if (threads < 0 || threads > MaxSolverThreads()) fail("threads", threads, ThreadRange());
  if (max_iterations < 1) fail("max iterations", max_iterations, ">= 1");
  if (time_step_levels < 1) fail("time-step levels", time_step_levels, ">= 1");
  if (resolution_levels < 1) fail("resolution levels", resolution_levels, ">= 1");
  if (!std::isfinite(time_step)) fail("dt", time_step, "finite (> 0, or <= 0 for the default)");
}

std::vector<TradeoffRow> RunTradeoff(const std::string& problem_name, const TradeoffOptions& o,
                                     std::ostream* progress) {
  o.Validate();
  std::vector<TradeoffRow> rows;
  const auto problem = MakeRefinedProblem(problem_name, o.refine);
  const Scene scene = problem->MakeScene();
  const int steps = o.steps > 0 ? o.steps : problem->default_steps();
  const double h0 = o.time_step > 0 ? o.time_step : problem->default_time_step();
  State initial;
  LinearLoss loss;
  {
    Simulator sim(scene, ReferenceOptions(h0, o.threads));
    initial = problem->InitialState(sim);
    loss = LinearLoss::Random(sim.num_dofs(), o.seed);
  }
  auto inputs_for = [&](double h, int k) {
    Simulator sim(scene, ReferenceOptions(h, o.threads));
    return problem->Inputs(sim, k);
  };
  const int dofs = scene.mesh.num_dofs();
  auto method_options = [&o](Method method, double tolerance, double h) {
    return Options(method, tolerance, h, o.threads, o.max_iterations);
  };

  if (o.sweep_tolerance) {
    Progress(progress, "[tradeoff] tolerance sweep: reference ...");
    const auto inputs = inputs_for(h0, steps);
    const RolloutMeasurement ref =
        MustSucceed(MeasureRollout(scene, ReferenceOptions(h0, o.threads), initial, inputs, loss), "tolerance sweep");
    const VectorXd ref_state = StackState(ref.final_state);
    for (Method method : o.methods)
      for (double tol : o.tolerances) {
        const RolloutMeasurement m = MeasureRollout(scene, method_options(method, tol, h0), initial, inputs, loss);
        TradeoffRow row = MakeRow("tolerance", method, "rel_tolerance", tol, m, dofs, steps);
        if (m.ok()) {
          row.state_rel_error = RelativeError(StackState(m.final_state), ref_state);
          row.grad_rel_error = RelativeError(m.gradient, ref.gradient);
        }
        Progress(progress, Describe(row));
        rows.push_back(row);
      }
  }

  if (o.sweep_time_step) {
    const int ref_steps = steps << o.time_step_levels;
    const double ref_h = h0 / (1 << o.time_step_levels);
    Progress(progress, "[tradeoff] time-step sweep: reference at h = " + std::to_string(ref_h) + " s (" +
                           std::to_string(ref_steps) + " steps) ...");
    const RolloutMeasurement ref = MustSucceed(
        MeasureRollout(scene, ReferenceOptions(ref_h, o.threads), initial, inputs_for(ref_h, ref_steps), loss),
        "time-step sweep");
    const VectorXd ref_state = StackState(ref.final_state);
    for (Method method : o.methods)
      for (int k = 0; k < o.time_step_levels; ++k) {
        const double h = h0 / (1 << k);
        const int n_steps = steps << k;
        const RolloutMeasurement m =
            MeasureRollout(scene, method_options(method, o.rel_tolerance, h), initial, inputs_for(h, n_steps), loss);
        TradeoffRow row = MakeRow("time_step", method, "time_step", h, m, dofs, n_steps);
        if (m.ok()) {
          row.state_rel_error = RelativeError(StackState(m.final_state), ref_state);
          row.grad_rel_error = RelativeError(m.gradient, ref.gradient);
        }
        Progress(progress, Describe(row));
        rows.push_back(row);
      }
  }

  if (o.sweep_resolution) {
    const VectorXd corner_weights = LinearLoss::Random(24, o.seed + 1).cx;  // one per corner DoF
    Progress(progress, "[tradeoff] resolution sweep: reference on the finest mesh ...");
    const CornerMeasurement ref =
        MeasureCorners(problem_name, o.refine, ReferenceOptions(h0, o.threads), o.steps, corner_weights);
    MustSucceed(ref.m, "resolution sweep");
    for (Method method : o.methods)
      for (int j = o.resolution_levels - 1; j >= 0; --j) {
        const SolverOptions so = method_options(method, o.rel_tolerance, h0);
        const CornerMeasurement c = MeasureCorners(problem_name, o.refine - 3 * j, so, o.steps, corner_weights);
        TradeoffRow row = MakeRow("resolution", method, "elements", c.elements, c.m, c.dofs, c.steps);
        if (c.m.ok()) {
          row.state_rel_error = RelativeError(c.displacement, ref.displacement);
          row.grad_rel_error = RelativeError(c.material_gradient, ref.material_gradient);
        }
        Progress(progress, Describe(row));
        rows.push_back(row);
      }
  }
  return rows;
}

nlohmann::json TradeoffToJson(const std::vector<TradeoffRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows) {
    const bool ok = r.failure.empty();
    auto num = [ok](double v) { return ok ? nlohmann::json(v) : nlohmann::json(nullptr); };
    out.push_back({{"sweep", r.sweep},
                   {"method", r.method},
                   {"parameter", r.parameter},
                   {"value", r.value},
                   {"seconds", num(r.seconds)},
                   {"state_rel_error", num(r.state_rel_error)},
                   {"grad_rel_error", num(r.grad_rel_error)},
                   {"status", ok ? std::string("ok") : "failed: " + r.failure},
                   {"forward_s", num(r.forward_s)},
                   {"backward_s", num(r.backward_s)},
                   {"iters_per_step", num(r.iters_per_step)},
                   {"dofs", r.dofs},
                   {"steps", r.steps}});
  }
  return out;
}

std::string GnuplotQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\n' || c == '\r') throw InvalidInputError("plot path contains a line break: give a plain file name");
    out += c;
    if (c == '\'') out += '\'';
  }
  return out + "'";
}

void RunGnuplot(const std::string& script, const std::string& png_path) {
  FILE* pipe = popen("gnuplot", "w");
  if (!pipe) throw std::runtime_error("could not start gnuplot");
  std::fwrite(script.data(), 1, script.size(), pipe);
  const int status = pclose(pipe);
  if (status != 0) {
    std::ostringstream msg;
    msg << "gnuplot failed (status " << status << ") while writing " << png_path;
    throw std::runtime_error(msg.str());
  }
  if (!std::filesystem::is_regular_file(png_path) || std::filesystem::file_size(png_path) == 0)
    throw std::runtime_error("gnuplot did not write " + png_path);
}

bool GnuplotAvailable() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/gnuplot";
    if (std::filesystem::is_regular_file(candidate) && access(candidate.c_str(), X_OK) == 0) return true;
  }
  return false;
}

void WriteTradeoffPlot(const std::vector<TradeoffRow>& rows, const std::string& png_path, const std::string& title) {
  if (!GnuplotAvailable())
    throw std::runtime_error(
        "--plot needs the gnuplot program, which is not on PATH (Debian: apt-get install "
        "gnuplot-nox), or leave out --plot");
  const std::vector<std::string> sweeps = {"tolerance", "time_step", "resolution"};
  std::vector<std::string> present;
  for (const auto& s : sweeps)
    for (const auto& r : rows)
      if (r.sweep == s && r.failure.empty()) {
        present.push_back(s);
        break;
      }
  if (present.empty()) throw std::runtime_error("nothing to plot: every tradeoff run failed");
  std::vector<std::string> methods;
  for (const auto& r : rows)
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);

  std::ostringstream script;
  script << "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size " << 500 * present.size()
         << ",900 } else { set terminal png size " << 500 * present.size() << ",900 }\n";
  script << "set output " << GnuplotQuote(png_path) << "\n";
  script << "set logscale xy\nset format y '10^{%L}'\nset grid\nset key top right font ',9'\n";
  // Data blocks: one per (sweep, method), columns seconds, state error, gradient error.
  auto block = [](const std::string& sweep, const std::string& method) {
    std::string name = "$" + sweep + "_" + method;
    for (char& c : name)
      if (c == '-') c = '_';
    return name;
  };
  for (const auto& s : present)
    for (const auto& m : methods) {
      script << block(s, m) << " << EOD\n";
      for (const auto& r : rows)
        if (r.sweep == s && r.method == m && r.failure.empty())
          script << r.seconds << " " << std::max(r.state_rel_error, 1e-17) << " " << std::max(r.grad_rel_error, 1e-17)
                 << "\n";
      script << "EOD\n";
    }
  script << "set multiplot layout 2," << present.size() << " title " << GnuplotQuote(title) << "\n";
  const char* what[2] = {"state", "gradient"};
  for (int row = 0; row < 2; ++row)
    for (const auto& s : present) {
      const std::string label = s == "tolerance"   ? "tolerance sweep"
                                : s == "time_step" ? "time-step sweep"
                                                   : "mesh-resolution sweep";
      script << "set title '" << label << "'\nset xlabel 'forward + backward time (s)'\nset ylabel '" << what[row]
             << " relative error'\nplot ";
      bool first = true;
      for (const auto& m : methods) {
        const bool any = std::any_of(rows.begin(), rows.end(), [&](const TradeoffRow& r) {
          return r.sweep == s && r.method == m && r.failure.empty();
        });
        if (!any) continue;  // every run failed: no curve (and no gnuplot warning)
        script << (first ? "" : ", ") << block(s, m) << " using 1:" << (row + 2) << " with linespoints title '" << m
               << "'";
        first = false;
      }
      script << "\n";
    }
  script << "unset multiplot\nset output\n";

  RunGnuplot(script.str(), png_path);
}

}  // namespace diffpd::problems
