#include "tools/table.h"

#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#include "cli/invalid_option.h"
#include "diffpd/error.h"
#include "paper/paper_rows.h"
#include "paper/row_evaluation.h"
#include "paper/row_optimisation.h"
#include "tools/openmp_waits.h"

#ifndef DIFFPD_SOURCE_DIR
#define DIFFPD_SOURCE_DIR "."
#endif

namespace diffpd::problems {
namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

bool IsNewton(Method m) { return m == Method::kNewtonCholesky || m == Method::kNewtonPcg || m == Method::kNewtonLdlt; }

std::string SizeName(RowSize size) { return size == RowSize::kPaper ? "paper" : "small"; }

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

// The first line of a shell command's output ("" if it fails).
std::string CommandOutput(const std::string& command) {
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return "";
  char buffer[256];
  std::string out;
  if (std::fgets(buffer, sizeof(buffer), pipe)) out = buffer;
  pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string SourceCommit() {
  const std::string dir = DIFFPD_SOURCE_DIR;
  std::string commit = CommandOutput("git -C '" + dir + "' rev-parse --short HEAD 2>/dev/null");
  if (commit.empty()) return "unknown";
  if (!CommandOutput("git -C '" + dir + "' status --porcelain --untracked-files=no 2>/dev/null").empty())
    commit += "-modified";
  return commit;
}

std::string MachineLabel() {
  utsname u{};
  const std::string arch = uname(&u) == 0 ? u.machine : "unknown";
  std::string model;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 1);
      model.erase(0, model.find_first_not_of(' '));
      break;
    }
  std::ostringstream s;
  s << std::thread::hardware_concurrency() << "-core " << arch;
  if (!model.empty()) s << ", " << model;
  s << ", " << OpenMpWaitsLabel();
  return s.str();
}

void Progress(std::ostream* out, const std::string& line) {
  if (out) *out << line << std::endl;
}

// Row metadata (sizes, the paper's numbers, notes) from the built row.
TableRowResult Describe(const PaperRow& row) {
  TableRowResult r;
  r.row = row.name;
  r.title = row.title;
  r.table_index = row.table_index;
  r.size = SizeName(row.size);
  r.nodes = row.scene.mesh.num_vertices();
  r.dofs = row.scene.mesh.num_dofs();
  r.elements = row.scene.mesh.num_elements();
  r.steps = row.steps;
  r.variables = row.num_variables();
  r.time_step = row.time_step;
  r.random_draws = static_cast<int>(row.random_draws.size());
  r.initial_guess = row.initial_guess == InitialGuess::kBestRandomDraw ? "the best of the 16 random draws"
                                                                       : "as the paper's script draws or sets it";
  r.paper = row.paper;
  r.notes = row.notes;
  return r;
}

// Mean of the random-draw losses, the baseline, the normalised losses and the
// speed-up, from what the row has measured.
void Summarise(const PaperRow& row, TableRowResult* r) {
  r->random_loss_mean.reset();
  r->baseline.reset();
  r->speedup.reset();
  if (r->random_draws > 0 && static_cast<int>(r->random_losses.size()) == r->random_draws) {
    double sum = 0;
    for (double l : r->random_losses) sum += l;
    r->random_loss_mean = sum / r->random_draws;
  }
  const TableMethodResult* pd = r->method(ToString(Method::kPdLbfgs));
  const bool pd_ok = pd && pd->failure.empty() && pd->evaluations > 0;
  if (row.baseline == LossBaseline::kZero)
    r->baseline = 0.0;
  else if (pd_ok && pd->optimisation && std::isfinite(pd->optimisation->final_loss))
    r->baseline = pd->optimisation->final_loss;  // DiffPD's final loss, as the paper
  else if (pd_ok)
    r->baseline = pd->loss;
  for (TableMethodResult& m : r->methods) {
    m.normalised_loss.reset();
    if (m.failure.empty() && m.evaluations > 0 && r->random_loss_mean && r->baseline &&
        *r->random_loss_mean != *r->baseline)
      m.normalised_loss = NormalisedLoss(m.loss, *r->random_loss_mean, *r->baseline);
    if (m.optimisation) {
      m.optimisation->normalised_loss.reset();
      if (r->random_loss_mean && r->baseline && *r->random_loss_mean != *r->baseline &&
          std::isfinite(m.optimisation->final_loss))
        m.optimisation->normalised_loss =
            NormalisedLoss(m.optimisation->final_loss, *r->random_loss_mean, *r->baseline);
    }
  }
  if (pd_ok) {
    std::optional<double> best;
    for (const TableMethodResult& m : r->methods) {
      const Method method = ParseMethod(m.method);
      if (!IsNewton(method) || !m.failure.empty() || m.evaluations == 0) continue;
      const double t = m.forward_s + m.backward_s;
      if (!best || t < *best) best = t;
    }
    if (best) r->speedup = *best / (pd->forward_s + pd->backward_s);
  }
}

class Budget {
 public:
  explicit Budget(double minutes) : start_(Clock::now()), seconds_(60 * minutes) {}
  bool spent() const {
    return seconds_ > 0 && std::chrono::duration<double>(Clock::now() - start_).count() >= seconds_;
  }

 private:
  Clock::time_point start_;
  double seconds_;
};

bool HoldsOptimisation(const TableResult& result) {
  for (const TableRowResult& r : result.rows)
    for (const TableMethodResult& m : r.methods)
      if (m.optimisation) return true;
  return false;
}

std::string Seconds(double s) {
  std::ostringstream out;
  out.precision(4);
  out << s << " s";
  return out.str();
}

}  // namespace

const TableMethodResult* TableRowResult::method(const std::string& name) const {
  for (const TableMethodResult& m : methods)
    if (m.method == name) return &m;
  return nullptr;
}

TableOptions::TableOptions() : rows(PaperRowNames()) {}

void TableOptions::Validate() const {
  if (rows.empty()) throw InvalidInputError("rows is empty: name at least one table row");
  const std::vector<std::string> valid = PaperRowNames();
  for (const std::string& r : rows)
    if (std::find(valid.begin(), valid.end(), r) == valid.end()) MakePaperRow(r, RowSize::kSmall);  // throws
  if (methods.empty()) throw InvalidInputError("methods is empty: name at least one method");
  for (Method m : methods)
    if (m == Method::kSemiImplicit)
      throw InvalidInputError(
          "method semi-implicit is not in the table: it has no tolerance (use pd-lbfgs, pd, newton-cholesky or "
          "newton-pcg)");
  if (threads < 0) ThrowInvalidOption("threads", threads, ">= 0");
  if (!std::isfinite(budget_minutes)) ThrowInvalidOption("budget minutes", budget_minutes, "finite (<= 0: none)");
  if (random_draws < 0) ThrowInvalidOption("random draws", random_draws, ">= 0");
  if (evaluations < 1) ThrowInvalidOption("evaluations", evaluations, ">= 1");
  if (newton_evaluations < 1) ThrowInvalidOption("newton evaluations", newton_evaluations, ">= 1");
  if (!std::isfinite(optimiser_minutes))
    ThrowInvalidOption("optimiser minutes", optimiser_minutes, "finite (<= 0: none)");
  if (optimise && optimizer == RowOptimizer::kIpopt && !DIFFPD_WITH_IPOPT)
    throw InvalidInputError(
        "optimizer ipopt: this build has no Ipopt adapter (configure with DIFFPD_WITH_IPOPT=ON, or use lbfgsb)");
}

TableResult RunTable(const TableOptions& options, const TableResult* previous,
                     const std::function<void(const TableResult&)>& checkpoint, std::ostream* progress) {
  options.Validate();
  // A report (measure = false) takes the file's settings as they are.
  if (previous && options.measure) {
    std::ostringstream msg;
    if (previous->size != SizeName(options.size))
      msg << "resume: the file holds the " << previous->size << " instances, this run asks for "
          << SizeName(options.size);
    else if (previous->masses != ToString(options.masses))
      msg << "resume: the file was measured with " << previous->masses << " masses, this run asks for "
          << ToString(options.masses);
    else if (previous->threads != options.threads)
      msg << "resume: the file was measured with " << previous->threads << " threads, this run asks for "
          << options.threads;
    else if (previous->evaluations != options.evaluations || previous->newton_evaluations != options.newton_evaluations)
      msg << "resume: the file has " << previous->evaluations << " evaluations per PD method and "
          << previous->newton_evaluations << " per Newton method, this run asks for " << options.evaluations << " and "
          << options.newton_evaluations;
    else if (options.optimise && HoldsOptimisation(*previous) && previous->optimizer != ToString(options.optimizer))
      msg << "resume: the file was optimised with " << previous->optimizer << ", this run asks for "
          << ToString(options.optimizer);
    if (!msg.str().empty()) throw InvalidInputError(msg.str());
  }
  const Budget budget(options.budget_minutes);
  TableResult result;
  result.date = UtcNow();
  result.commit = SourceCommit();
  result.machine = MachineLabel();
  result.command = options.command;
  result.optimizer = ToString(options.optimizer);
  if (previous) {
    result.resumed_runs = previous->resumed_runs;
    if (options.measure)
      result.resumed_runs.push_back(result.date + ", commit " + result.commit + ", " + result.machine +
                                    (options.command.empty() ? "" : ": " + options.command));
    result.date = previous->date;
    result.commit = previous->commit;
    result.machine = previous->machine;
    result.command = previous->command;
    // A file that holds no optimisation yet takes this run's optimizer.
    if (!options.measure || HoldsOptimisation(*previous)) result.optimizer = previous->optimizer;
  }
  const bool report = previous && !options.measure;
  result.threads = report ? previous->threads : options.threads;
  const RowSize size = report ? (previous->size == "small" ? RowSize::kSmall : RowSize::kPaper) : options.size;
  result.size = SizeName(size);
  result.masses = previous ? previous->masses : ToString(options.masses);
  result.evaluations = report ? previous->evaluations : options.evaluations;
  result.newton_evaluations = report ? previous->newton_evaluations : options.newton_evaluations;
  // The rows to run, then those of the previous file that this run does not
  // name (kept as they are).
  std::vector<std::string> names = options.rows;
  if (previous)
    for (const TableRowResult& r : previous->rows)
      if (std::find(names.begin(), names.end(), r.row) == names.end()) names.push_back(r.row);
  auto save = [&] {
    if (checkpoint) checkpoint(result);
  };

  if (!options.measure) result.budget_exhausted = previous && previous->budget_exhausted;
  for (const std::string& name : names) {
    const bool requested =
        options.measure && std::find(options.rows.begin(), options.rows.end(), name) != options.rows.end();
    PaperRow row = MakePaperRow(name, size);
    SetRowMasses(&row, previous ? ParseMassLumping(previous->masses) : options.masses);
    result.rows.push_back(Describe(row));
    TableRowResult& out = result.rows.back();
    const TableRowResult* before = nullptr;
    if (previous)
      for (const TableRowResult& r : previous->rows)
        if (r.row == name) before = &r;
    if (before) {
      if (!before->initial_guess.empty()) out.initial_guess = before->initial_guess;
      out.random_losses = before->random_losses;
      if (static_cast<int>(out.random_losses.size()) > out.random_draws) out.random_losses.resize(out.random_draws);
      for (const TableMethodResult& m : before->methods)
        if (m.complete) out.methods.push_back(m);
    }
    // Whether `m` optimises this row in this run (PD methods of optimised rows).
    const auto optimises = [&](Method m) { return options.optimise && row.budget.optimised && !IsNewton(m); };
    const auto method_done = [&](Method m) {
      const TableMethodResult* r = out.method(ToString(m));
      return r && r->complete && (!optimises(m) || r->optimisation || !r->failure.empty());
    };
    bool all_done = static_cast<int>(out.random_losses.size()) == out.random_draws;
    for (Method m : options.methods) all_done = all_done && method_done(m);
    // Nothing for this run: every method done and no draw it may evaluate left.
    bool nothing_left = static_cast<int>(out.random_losses.size()) == out.random_draws || options.random_draws == 0;
    for (Method m : options.methods) nothing_left = nothing_left && method_done(m);
    if (!requested || nothing_left || result.budget_exhausted) {
      out.complete = all_done;
      Summarise(row, &out);
      continue;
    }
    {
      std::ostringstream line;
      line << "[table] " << name << ": " << out.dofs << " DoFs, " << out.elements << " elements, " << out.steps
           << " steps of " << out.time_step << " s, " << out.variables << " variables, " << options.threads
           << " threads";
      Progress(progress, line.str());
    }
    const SolverOptions pd_options = row.Options(Method::kPdLbfgs, options.threads);
    if (row.prepare) {
      const auto start = Clock::now();
      row.Prepare(pd_options);
      Progress(progress, "[table] " + name + ": preparatory simulations (pd-lbfgs) took " +
                             Seconds(std::chrono::duration<double>(Clock::now() - start).count()));
    }

    // The normalisation: the random draws' losses with pd-lbfgs.
    const int draws = std::min(out.random_draws, static_cast<int>(out.random_losses.size()) + options.random_draws);
    if (static_cast<int>(out.random_losses.size()) < draws) {
      Simulator sim(row.scene, pd_options);
      for (int d = static_cast<int>(out.random_losses.size()); d < draws; ++d) {
        if (budget.spent()) break;
        try {
          const RowEvaluation e = EvaluateRow(row, &sim, row.random_draws[d], false);
          out.random_losses.push_back(e.loss);
          std::ostringstream line;
          line << "[table] " << name << " random draw " << d + 1 << "/" << out.random_draws << ": loss " << e.loss
               << ", forward " << Seconds(e.forward_s);
          Progress(progress, line.str());
        } catch (const SolverError& e) {
          Progress(progress, "[table] " + name + " random draw " + std::to_string(d + 1) + " failed: " + e.what());
          out.random_losses.push_back(std::nan(""));
        }
        save();
      }
    }
    if (static_cast<int>(out.random_losses.size()) < draws) {
      result.budget_exhausted = true;
      Summarise(row, &out);
      save();
      continue;
    }
    if (row.initial_guess == InitialGuess::kBestRandomDraw) {
      if (static_cast<int>(out.random_losses.size()) == out.random_draws) {
        int best = 0;
        for (int d = 1; d < out.random_draws; ++d)
          if (out.random_losses[d] < out.random_losses[best]) best = d;
        row.SetInitial(row.random_draws[best]);
        out.initial_guess = "the best of the 16 random draws (draw " + std::to_string(best + 1) + ")";
      } else {
        out.initial_guess =
            "the first draw after seed 42 (the random draws, of which the paper takes the best, were "
            "not all evaluated)";
      }
      Progress(progress, "[table] " + name + ": x_init is " + out.initial_guess);
    }

    // The methods.
    const VectorXd x = row.initial();
    for (Method method : options.methods) {
      if (method_done(method) || budget.spent()) continue;
      TableMethodResult m;
      m.method = ToString(method);
      const TableMethodResult* measured = out.method(m.method);
      const bool at_x_init_done = measured && measured->complete;
      if (at_x_init_done) m = *measured;
      const int count = IsNewton(method) ? options.newton_evaluations : options.evaluations;
      try {
        Simulator sim(row.scene, row.Options(method, options.threads));
        double forward = 0, backward = 0;
        for (int k = 0; k < count && !at_x_init_done; ++k) {
          if (budget.spent()) break;
          const RowEvaluation e = EvaluateRow(row, &sim, x, true);
          forward += e.forward_s;
          backward += e.backward_s;
          m.forward_samples.push_back(e.forward_s);
          m.backward_samples.push_back(e.backward_s);
          ++m.evaluations;
          m.forward_s = forward / m.evaluations;
          m.backward_s = backward / m.evaluations;
          m.loss = e.loss;
          m.iterations_per_step = e.iterations_per_step;
          m.newton_fallback_steps = e.newton_fallback_steps;
          m.backward_iterations_per_step = e.backward_iterations_per_step;
          m.backward_fallbacks = e.backward_fallbacks;
          std::ostringstream line;
          line << "[table] " << name << " " << m.method << " evaluation " << k + 1 << "/" << count << ": loss "
               << e.loss << ", |grad| " << e.gradient.norm() << ", forward " << Seconds(e.forward_s) << ", backward "
               << Seconds(e.backward_s) << ", " << e.iterations_per_step << " iterations/step, "
               << e.backward_iterations_per_step << " backward iterations/step";
          Progress(progress, line.str());
        }
        m.complete = m.evaluations == count;
        if (m.complete && optimises(method) && !m.optimisation && !budget.spent()) {
          RowOptimisationOptions o;
          o.optimizer = options.optimizer;
          o.max_evaluations = options.optimiser_evaluations;
          o.budget_seconds = 60 * options.optimiser_minutes;
          o.on_evaluation = [&](long k, double loss, double forward_s) {
            std::ostringstream line;
            line << "[table] " << name << " " << m.method << " optimiser evaluation " << k << ": loss " << loss
                 << ", forward " << Seconds(forward_s);
            Progress(progress, line.str());
          };
          const RowOptimisationResult r = OptimiseRow(row, row.Options(method, options.threads), o);
          TableOptimisation t;
          t.optimizer = r.optimizer;
          t.status = r.status;
          t.stopped_by = r.stopped_by;
          t.iterations = r.iterations;
          t.evaluations = r.evaluations;
          t.gradients = r.gradients;
          t.failed_evaluations = r.failed_evaluations;
          t.forward_s = r.forward_s;
          t.backward_s = r.backward_s;
          t.total_s = r.total_s;
          t.initial_loss = r.initial_loss;
          t.final_loss = r.final_loss;
          t.loss_history = r.loss_history;
          m.optimisation = t;
          std::ostringstream line;
          line << "[table] " << name << " " << m.method << " optimiser " << r.optimizer << ": " << r.status
               << " (stopped by " << r.stopped_by << "), " << r.iterations << " iterations, " << r.evaluations
               << " evaluations, " << r.gradients << " gradients, loss " << r.initial_loss << " -> " << r.final_loss
               << ", " << Seconds(r.total_s);
          Progress(progress, line.str());
        }
      } catch (const SolverError& e) {
        m.failure = std::string(ToString(e.status())) + ": " + e.what();
        m.complete = true;
      } catch (const InvalidInputError& e) {
        m.failure = std::string("invalid input: ") + e.what();
        m.complete = true;
      }
      if (!m.failure.empty()) Progress(progress, "[table] " + name + " " + m.method + " failed: " + m.failure);
      if (!m.complete) result.budget_exhausted = true;
      if (m.evaluations > 0 || !m.failure.empty()) {
        auto it = std::find_if(out.methods.begin(), out.methods.end(),
                               [&](const TableMethodResult& r) { return r.method == m.method; });
        if (it != out.methods.end())
          *it = m;
        else
          out.methods.push_back(m);
      }
      Summarise(row, &out);
      save();
    }
    all_done = static_cast<int>(out.random_losses.size()) == out.random_draws;
    for (Method m : options.methods) all_done = all_done && method_done(m);
    out.complete = all_done;
    // A row left incomplete on purpose (fewer draws) does not stop the run.
    if (!all_done && budget.spent()) result.budget_exhausted = true;
    Summarise(row, &out);
    save();
  }
  return result;
}

// ---- JSON --------------------------------------------------------------------

namespace {

json Optional(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }
json OptionalInt(const std::optional<int>& v) { return v ? json(*v) : json(nullptr); }

json PaperMethodJson(const PaperMethodNumbers& p) {
  return {{"forward_s", p.forward_s},
          {"backward_s", p.backward_s},
          {"evaluations", OptionalInt(p.evaluations)},
          {"loss", Optional(p.loss)}};
}

// A number that JSON cannot hold (NaN, a failed draw) is written as null.
json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

template <typename T>
T Field(const json& j, const std::string& key, const std::string& where) {
  if (!j.is_object() || !j.contains(key))
    throw InvalidInputError("table JSON: " + where + " has no field '" + key + "'");
  try {
    return j.at(key).get<T>();
  } catch (const json::exception&) {
    throw InvalidInputError("table JSON: " + where + "." + key + " has the wrong type");
  }
}

json OptimisationJson(const TableOptimisation& t) {
  json history = json::array();
  for (double l : t.loss_history) history.push_back(Number(l));
  return {{"optimizer", t.optimizer},
          {"status", t.status},
          {"stopped_by", t.stopped_by},
          {"iterations", t.iterations},
          {"evaluations", t.evaluations},
          {"gradients", t.gradients},
          {"failed_evaluations", t.failed_evaluations},
          {"forward_s", t.forward_s},
          {"backward_s", t.backward_s},
          {"total_s", t.total_s},
          {"initial_loss", Number(t.initial_loss)},
          {"final_loss", Number(t.final_loss)},
          {"normalised_loss", Optional(t.normalised_loss)},
          {"loss_history", history}};
}

double NumberOrNan(const json& j, const std::string& key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
}

TableOptimisation OptimisationFromJson(const json& j, const std::string& where) {
  TableOptimisation t;
  // Optimisations written before the optimizer was recorded are Ipopt's.
  t.optimizer = j.contains("optimizer") ? Field<std::string>(j, "optimizer", where) : "ipopt";
  t.status = Field<std::string>(j, "status", where);
  t.stopped_by = Field<std::string>(j, "stopped_by", where);
  t.iterations = Field<int>(j, "iterations", where);
  t.evaluations = Field<long>(j, "evaluations", where);
  t.gradients = Field<long>(j, "gradients", where);
  t.failed_evaluations = Field<long>(j, "failed_evaluations", where);
  t.forward_s = Field<double>(j, "forward_s", where);
  t.backward_s = Field<double>(j, "backward_s", where);
  t.total_s = Field<double>(j, "total_s", where);
  t.initial_loss = NumberOrNan(j, "initial_loss");
  t.final_loss = NumberOrNan(j, "final_loss");
  for (const json& l : Field<json>(j, "loss_history", where))
    t.loss_history.push_back(l.is_number() ? l.get<double>() : std::nan(""));
  return t;
}

}  // namespace

json TableToJson(const TableResult& result) {
  json rows = json::array();
  for (const TableRowResult& r : result.rows) {
    json methods = json::array();
    for (const TableMethodResult& m : r.methods)
      methods.push_back({{"method", m.method},
                         {"status", m.failure.empty() ? std::string("ok") : "failed: " + m.failure},
                         {"failure", m.failure},
                         {"evaluations", m.evaluations},
                         {"forward_s", m.forward_s},
                         {"backward_s", m.backward_s},
                         {"forward_samples_s", m.forward_samples},
                         {"backward_samples_s", m.backward_samples},
                         {"loss", Number(m.loss)},
                         {"normalised_loss", Optional(m.normalised_loss)},
                         {"iterations_per_step", m.iterations_per_step},
                         {"newton_fallback_steps", m.newton_fallback_steps},
                         {"backward_iterations_per_step", m.backward_iterations_per_step},
                         {"backward_fallbacks", m.backward_fallbacks},
                         {"complete", m.complete},
                         {"optimisation", m.optimisation ? OptimisationJson(*m.optimisation) : json(nullptr)}});
    json random = json::array();
    for (double l : r.random_losses) random.push_back(Number(l));
    rows.push_back({{"row", r.row},
                    {"title", r.title},
                    {"table_index", r.table_index},
                    {"size", r.size},
                    {"nodes", r.nodes},
                    {"dofs", r.dofs},
                    {"elements", r.elements},
                    {"steps", r.steps},
                    {"time_step", r.time_step},
                    {"variables", r.variables},
                    {"evaluation_point", r.evaluation_point},
                    {"initial_guess", r.initial_guess},
                    {"random_draws", r.random_draws},
                    {"random_losses", random},
                    {"random_loss_mean", Optional(r.random_loss_mean)},
                    {"baseline", Optional(r.baseline)},
                    {"methods", methods},
                    {"speedup", Optional(r.speedup)},
                    {"paper",
                     {{"newton_pcg", PaperMethodJson(r.paper.newton_pcg)},
                      {"newton_cholesky", PaperMethodJson(r.paper.newton_cholesky)},
                      {"diffpd", PaperMethodJson(r.paper.diffpd)},
                      {"speedup", r.paper.speedup}}},
                    {"notes", r.notes},
                    {"complete", r.complete}});
  }
  return {{"date", result.date},
          {"commit", result.commit},
          {"machine", result.machine},
          {"threads", result.threads},
          {"size", result.size},
          {"masses", result.masses},
          {"optimizer", result.optimizer},
          {"command", result.command},
          {"evaluations", result.evaluations},
          {"newton_evaluations", result.newton_evaluations},
          {"budget_exhausted", result.budget_exhausted},
          {"resumed_runs", result.resumed_runs},
          {"rows", rows}};
}

TableResult TableFromJson(const json& j) {
  TableResult result;
  result.date = Field<std::string>(j, "date", "the document");
  result.commit = Field<std::string>(j, "commit", "the document");
  result.machine = Field<std::string>(j, "machine", "the document");
  result.threads = Field<int>(j, "threads", "the document");
  result.size = Field<std::string>(j, "size", "the document");
  // Files written before masses were an option hold lumped rows.
  if (j.contains("masses")) result.masses = Field<std::string>(j, "masses", "the document");
  // Files written before these were stored: Ipopt, no command.
  if (j.contains("optimizer")) result.optimizer = Field<std::string>(j, "optimizer", "the document");
  if (j.contains("command")) result.command = Field<std::string>(j, "command", "the document");
  result.evaluations = Field<int>(j, "evaluations", "the document");
  result.newton_evaluations = Field<int>(j, "newton_evaluations", "the document");
  result.budget_exhausted = Field<bool>(j, "budget_exhausted", "the document");
  if (j.contains("resumed_runs"))
    result.resumed_runs = Field<std::vector<std::string>>(j, "resumed_runs", "the document");
  const json rows = Field<json>(j, "rows", "the document");
  if (!rows.is_array()) throw InvalidInputError("table JSON: the document.rows has the wrong type");
  for (size_t i = 0; i < rows.size(); ++i) {
    const json& rj = rows[i];
    const std::string where = "rows[" + std::to_string(i) + "]";
    TableRowResult r;
    r.row = Field<std::string>(rj, "row", where);
    r.size = Field<std::string>(rj, "size", where);
    r.complete = Field<bool>(rj, "complete", where);
    if (rj.contains("initial_guess")) r.initial_guess = Field<std::string>(rj, "initial_guess", where);
    for (const json& l : Field<json>(rj, "random_losses", where))
      r.random_losses.push_back(l.is_null() ? std::nan("") : l.get<double>());
    const json methods = Field<json>(rj, "methods", where);
    for (size_t k = 0; k < methods.size(); ++k) {
      const json& mj = methods[k];
      const std::string mwhere = where + ".methods[" + std::to_string(k) + "]";
      TableMethodResult m;
      m.method = Field<std::string>(mj, "method", mwhere);
      m.failure = Field<std::string>(mj, "failure", mwhere);
      m.evaluations = Field<int>(mj, "evaluations", mwhere);
      m.forward_s = Field<double>(mj, "forward_s", mwhere);
      m.backward_s = Field<double>(mj, "backward_s", mwhere);
      // Optional: files written before the samples were recorded lack them.
      if (mj.contains("forward_samples_s"))
        m.forward_samples = Field<std::vector<double>>(mj, "forward_samples_s", mwhere);
      if (mj.contains("backward_samples_s"))
        m.backward_samples = Field<std::vector<double>>(mj, "backward_samples_s", mwhere);
      m.loss = mj.contains("loss") && mj["loss"].is_number() ? mj["loss"].get<double>() : std::nan("");
      m.iterations_per_step = Field<double>(mj, "iterations_per_step", mwhere);
      m.newton_fallback_steps = Field<int>(mj, "newton_fallback_steps", mwhere);
      if (mj.contains("backward_iterations_per_step"))
        m.backward_iterations_per_step = Field<double>(mj, "backward_iterations_per_step", mwhere);
      if (mj.contains("backward_fallbacks")) m.backward_fallbacks = Field<int>(mj, "backward_fallbacks", mwhere);
      m.complete = Field<bool>(mj, "complete", mwhere);
      if (mj.contains("optimisation") && !mj["optimisation"].is_null())
        m.optimisation = OptimisationFromJson(mj["optimisation"], mwhere + ".optimisation");
      r.methods.push_back(m);
    }
    result.rows.push_back(r);
  }
  return result;
}

}  // namespace diffpd::problems
