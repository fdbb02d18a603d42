#include "tools/table_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "paper/paper_row.h"
#include "tools/tradeoff.h"

namespace diffpd::problems {
namespace {

// The paper's entry for one of this library's methods (pd-lbfgs <-> DiffPD);
// nullptr for a method the paper did not run.
const PaperMethodNumbers* PaperEntry(const TableRowResult& row, const std::string& method) {
  if (method == "pd-lbfgs") return &row.paper.diffpd;
  if (method == "newton-pcg") return &row.paper.newton_pcg;
  if (method == "newton-cholesky") return &row.paper.newton_cholesky;
  return nullptr;
}

std::string Fixed(double v, int digits = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

std::string Sci(const std::optional<double>& v) {
  if (!v || !std::isfinite(*v)) return "-";
  std::ostringstream s;
  s.precision(2);
  if (*v == 0)
    s << "0";
  else
    s << std::scientific << *v;
  return s.str();
}

std::string Seconds(double v) { return v >= 100 ? Fixed(v, 0) : v >= 1 ? Fixed(v, 1) : Fixed(v, 3); }

struct Cells {
  std::string row, dofs, method, forward, paper_forward, backward, paper_backward, evals, paper_evals, loss, paper_loss,
      speedup, paper_speedup;
};

std::vector<Cells> TableCells(const TableResult& result) {
  std::vector<Cells> lines;
  for (const TableRowResult& r : result.rows) {
    bool first = true;
    std::vector<std::string> names;
    for (const TableMethodResult& m : r.methods) names.push_back(m.method);
    if (names.empty()) names.push_back("(not measured)");
    for (const std::string& name : names) {
      Cells c;
      c.row = first ? std::to_string(r.table_index) + " " + r.row : "";
      c.dofs = first ? std::to_string(r.dofs) + " / " + std::to_string(r.steps) : "";
      c.method = name;
      const TableMethodResult* m = r.method(name);
      const PaperMethodNumbers* p = PaperEntry(r, name);
      const bool ok = m && m->failure.empty() && m->evaluations > 0;
      c.forward = ok ? Seconds(m->forward_s) : m && !m->failure.empty() ? "failed" : "-";
      c.backward = ok ? Seconds(m->backward_s) : "-";
      // An optimised method: the optimiser's evaluations and final loss;
      // else the evaluations at x_init in parentheses and the loss there.
      const bool optimised = ok && m->optimisation;
      c.evals = optimised ? std::to_string(m->optimisation->evaluations)
                : ok      ? "(" + std::to_string(m->evaluations) + ")"
                          : "-";
      c.loss = optimised ? Sci(m->optimisation->normalised_loss) : ok ? "(" + Sci(m->normalised_loss) + ")" : "-";
      c.paper_forward = p ? Fixed(p->forward_s) : "-";
      c.paper_backward = p ? Fixed(p->backward_s) : "-";
      c.paper_evals = p && p->evaluations ? std::to_string(*p->evaluations) : "-";
      c.paper_loss = p ? Sci(p->loss) : "-";
      // The first line: the best Newton over pd-lbfgs; a Newton method's own
      // line: its own time over pd-lbfgs's.
      const TableMethodResult* pd = r.method("pd-lbfgs");
      const bool pd_ok = pd && pd->failure.empty() && pd->evaluations > 0;
      if (first)
        c.speedup = r.speedup ? Fixed(*r.speedup) + "x" : "-";
      else if (ok && pd_ok && name.rfind("newton", 0) == 0)
        c.speedup = Fixed((m->forward_s + m->backward_s) / (pd->forward_s + pd->backward_s)) + "x";
      c.paper_speedup = first ? Fixed(r.paper.speedup, 0) + "x" : "";
      lines.push_back(c);
      first = false;
    }
  }
  return lines;
}

const char* kHeader[13] = {"row",   "DoFs / steps", "method",      "fwd s", "paper",    "bwd s", "paper",
                           "evals", "paper",        "loss (norm)", "paper", "speed-up", "paper"};

std::vector<std::string> Row(const Cells& c) {
  return {c.row,   c.dofs,        c.method, c.forward,    c.paper_forward, c.backward,     c.paper_backward,
          c.evals, c.paper_evals, c.loss,   c.paper_loss, c.speedup,       c.paper_speedup};
}

// Notes shared by every row (printed once) and the rest per row.
void SplitNotes(const TableResult& result, std::vector<std::string>* shared,
                std::vector<std::pair<std::string, std::vector<std::string>>>* own) {
  if (result.rows.empty()) return;
  for (const std::string& note : result.rows[0].notes) {
    const bool everywhere = std::all_of(result.rows.begin(), result.rows.end(), [&](const TableRowResult& r) {
      return std::find(r.notes.begin(), r.notes.end(), note) != r.notes.end();
    });
    if (everywhere) shared->push_back(note);
  }
  for (const TableRowResult& r : result.rows) {
    std::vector<std::string> notes;
    for (const std::string& note : r.notes)
      if (std::find(shared->begin(), shared->end(), note) == shared->end()) notes.push_back(note);
    if (!notes.empty()) own->push_back({r.row, notes});
  }
}

// How the rows were optimised, by the optimizer that did it.
std::string OptimiserDescription(const std::string& optimizer) {
  if (optimizer == "lbfgsb")
    return "L-BFGS-B, the paper's optimiser, with the row's memory, ftol, gtol, iteration limit, evaluation budget "
           "and bounds";
  return "Ipopt, limited-memory Hessian, the row's bounds and evaluation budget, stopped by L-BFGS-B's ftol test";
}

std::string Explanation(const TableResult& result) {
  std::ostringstream s;
  s << "Seconds are wall-clock means per evaluation of the loss and its gradient at x_init (" << result.evaluations
    << " evaluations per PD method, " << result.newton_evaluations
    << " per Newton method); the paper's are means over its whole optimisation, on 8 threads. evals and loss "
       "(norm): for a method that optimised the row ("
    << OptimiserDescription(result.optimizer)
    << "), its loss evaluations and final loss; in parentheses, a method timed at x_init only: "
       "its evaluations there and the loss at x_init. loss (norm) is (L - l) / (L_random - l), L_random the mean "
       "pd-lbfgs loss of the row's 16 random draws, l = 0 or pd-lbfgs's final loss as the paper's row says. "
       "speed-up: best Newton (forward + backward at x_init) over pd-lbfgs (at x_init); on a Newton method's line, "
       "its own.";
  return s.str();
}

// "<status>, stopped by <what>, 12 iterations, 15 evaluations, ..." of one optimisation.
std::string OptimisationLine(const TableOptimisation& t) {
  std::ostringstream s;
  s << t.optimizer << ", " << t.status << " (stopped by " << t.stopped_by << "), " << t.iterations << " iterations, "
    << t.evaluations << " evaluations (" << t.failed_evaluations << " failed), " << t.gradients
    << " gradients, forward " << Seconds(t.forward_s) << " s and backward " << Seconds(t.backward_s)
    << " s per evaluation, " << Seconds(t.total_s) << " s in all, loss " << Sci(t.initial_loss) << " -> "
    << Sci(t.final_loss);
  return s.str();
}

}  // namespace

void PrintTable(const TableResult& result, std::FILE* out) {
  std::fprintf(out, "# DiffPD paper table, %s instances, %s masses: %s, commit %s, %s, %d threads\n",
               result.size.c_str(), result.masses.c_str(), result.date.c_str(), result.commit.c_str(),
               result.machine.c_str(), result.threads);
  if (!result.command.empty()) std::fprintf(out, "# command: %s\n", result.command.c_str());
  for (const std::string& run : result.resumed_runs) std::fprintf(out, "# resumed %s\n", run.c_str());
  const std::vector<Cells> cells = TableCells(result);
  std::vector<size_t> width(13);
  for (int k = 0; k < 13; ++k) width[k] = std::string(kHeader[k]).size();
  for (const Cells& c : cells) {
    const auto row = Row(c);
    for (int k = 0; k < 13; ++k) width[k] = std::max(width[k], row[k].size());
  }
  auto print = [&](const std::vector<std::string>& row) {
    for (int k = 0; k < 13; ++k)
      std::fprintf(out, k < 3 ? "%-*s  " : "%*s  ", static_cast<int>(width[k]), row[k].c_str());
    std::fprintf(out, "\n");
  };
  print(std::vector<std::string>(kHeader, kHeader + 13));
  for (const Cells& c : cells) print(Row(c));
  for (const TableRowResult& r : result.rows)
    for (const TableMethodResult& m : r.methods)
      if (!m.failure.empty())
        std::fprintf(out, "# %s %s failed: %s\n", r.row.c_str(), m.method.c_str(), m.failure.c_str());
  for (const TableRowResult& r : result.rows)
    for (const TableMethodResult& m : r.methods)
      if (m.optimisation)
        std::fprintf(out, "# %s %s optimiser: %s\n", r.row.c_str(), m.method.c_str(),
                     OptimisationLine(*m.optimisation).c_str());
  if (result.budget_exhausted) std::fprintf(out, "# the time budget ran out: rows marked '-' were not measured\n");
  std::fprintf(out, "# %s\n", Explanation(result).c_str());
  std::vector<std::string> shared;
  std::vector<std::pair<std::string, std::vector<std::string>>> own;
  SplitNotes(result, &shared, &own);
  for (const std::string& note : shared) std::fprintf(out, "# every row: %s\n", note.c_str());
  for (const auto& [row, notes] : own)
    for (const std::string& note : notes) std::fprintf(out, "# %s: %s\n", row.c_str(), note.c_str());
}

std::string TableMarkdown(const TableResult& result, const std::string& command) {
  std::ostringstream s;
  s << "Measured " << result.date << ", commit " << result.commit << ", " << result.machine << ", " << result.threads
    << " threads, " << result.size << " instances, " << result.masses << " masses:\n\n    "
    << (result.command.empty() ? command : result.command) << "\n\n";
  for (const std::string& run : result.resumed_runs) s << "Resumed " << run << "\n\n";
  if (!result.command.empty() && command != result.command) s << "Reported by:\n\n    " << command << "\n\n";
  s << "|";
  for (const char* h : kHeader) s << " " << h << " |";
  s << "\n|";
  for (int k = 0; k < 13; ++k) s << (k < 3 ? " --- |" : " ---: |");
  s << "\n";
  for (const Cells& c : TableCells(result)) {
    s << "|";
    for (const std::string& cell : Row(c)) s << " " << cell << " |";
    s << "\n";
  }
  s << "\n" << Explanation(result) << "\n";
  for (const TableRowResult& r : result.rows)
    for (const TableMethodResult& m : r.methods)
      if (!m.failure.empty()) s << "\n- " << r.row << ", " << m.method << " failed: " << m.failure;
  for (const TableRowResult& r : result.rows)
    for (const TableMethodResult& m : r.methods)
      if (m.optimisation)
        s << "\n- " << r.row << ", " << m.method << " optimiser: " << OptimisationLine(*m.optimisation);
  if (result.budget_exhausted) s << "\n\nThe time budget ran out; cells marked '-' were not measured.";
  std::vector<std::string> shared;
  std::vector<std::pair<std::string, std::vector<std::string>>> own;
  SplitNotes(result, &shared, &own);
  s << "\n\nHow this library's rows differ from the original code:\n\n";
  for (const std::string& note : shared) s << "- every row: " << note << "\n";
  for (const auto& [row, notes] : own)
    for (const std::string& note : notes) s << "- " << row << ": " << note << "\n";
  return s.str();
}

void WriteTablePlot(const TableResult& result, const std::string& png_path) {
  if (!GnuplotAvailable())
    throw std::runtime_error(
        "--plot needs the gnuplot program, which is not on PATH (Debian: apt-get install gnuplot-nox), or leave out "
        "--plot");
  const std::vector<std::string> methods = {"pd-lbfgs", "newton-pcg", "newton-cholesky"};
  std::ostringstream data;
  double low = 1e300;
  bool any = false;
  for (const TableRowResult& r : result.rows) {
    // Double quotes: gnuplot keeps single quotes in inline data as part of the label.
    data << "\"" << r.row << "\"";
    for (const std::string& name : methods) {
      const TableMethodResult* m = r.method(name);
      const PaperMethodNumbers* p = PaperEntry(r, name);
      if (m && m->failure.empty() && m->evaluations > 0) {
        const double t = m->forward_s + m->backward_s;
        data << " " << t;
        low = std::min(low, t);
        any = true;
      } else {
        data << " -";
      }
      data << " " << p->forward_s + p->backward_s;
      low = std::min(low, p->forward_s + p->backward_s);
    }
    data << "\n";
  }
  if (!any) throw std::runtime_error("nothing to plot: no method was measured");
  const double bottom = std::pow(10.0, std::floor(std::log10(low)));
  std::ostringstream script;
  script << "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size 1200,600 } else { set "
            "terminal png size 1200,600 }\n";
  script << "set output " << GnuplotQuote(png_path) << "\n";
  script << "set title "
         << GnuplotQuote("Seconds per evaluation (forward + backward): this library on " +
                         std::to_string(result.threads) + " threads (" + result.date.substr(0, 10) + ", " +
                         result.commit + ") vs. the paper on 8")
         << "\n";
  script << "set datafile missing '-'\nset style data histograms\nset style histogram clustered gap 1\n"
            "set style fill solid 0.9 border -1\nset boxwidth 0.9\nset logscale y\nset yrange ["
         << bottom << ":*]\nset ylabel 'seconds per evaluation'\nset grid ytics\nset key top left font ',9'\n"
         << "set xtics rotate by -20 font ',10'\n";
  script << "$data << EOD\n" << data.str() << "EOD\n";
  const char* colours[3] = {"#1b9e77", "#7570b3", "#d95f02"};
  const char* paper_names[3] = {"DiffPD", "Newton-PCG", "Newton-Cholesky"};
  script << "plot ";
  for (int k = 0; k < 3; ++k) {
    script << (k ? ", " : "") << "$data using " << 2 + 2 * k << ":xtic(1) title '" << methods[k] << " (here)' lc rgb '"
           << colours[k] << "', $data using " << 3 + 2 * k << " title '" << paper_names[k] << " (paper)' lc rgb '"
           << colours[k] << "' fill pattern 4";
  }
  script << "\nset output\n";
  RunGnuplot(script.str(), png_path);
}

}  // namespace diffpd::problems
