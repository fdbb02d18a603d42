// `diffpd table`: the command-line edge of table.h and table_report.h.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli/commands.h"
#include "diffpd/error.h"
#include "paper/paper_rows.h"
#include "tools/bench.h"
#include "tools/table.h"
#include "tools/table_report.h"

namespace diffpd::problems {
namespace {

constexpr const char* kTableFooter = R"(
Rows: cantilever, rolling-sphere, plant, bouncing-ball, bunny, routing-tendon,
torus, quadruped, cow, starfish, shark (the DiffPD paper's Table, built as
PROBLEMS.md states, at the paper's size unless --small; the swimmers are
starfish-control's and shark-control's, timed at the initial controller). Per row: the preparatory simulations
(targets) and the 16 random draws' losses (pd-lbfgs, forward only: the
normalisation), then per method --evaluations (Newton: --newton-evaluations)
evaluations of the loss and its gradient at x_init on a fresh simulator.
Columns: mean forward and backward seconds per evaluation, evaluations, loss
at x_init normalised as the paper does, speed-up (best Newton over pd-lbfgs),
each beside the paper's number (8 threads, means over its optimisation).
--optimise then optimises every optimised row with each PD method by
--optimizer: lbfgsb (L-BFGS-B, the paper's optimiser, with the row's scipy
settings) or ipopt (limited-memory Hessian, stopped by L-BFGS-B's ftol test).
--json FILE is rewritten after every draw and method, so an interrupted run
keeps what it measured; --resume reads FILE back and skips what is done.
A progress line per evaluation goes to stderr.)";

struct TableArgs {
  std::vector<std::string> rows = PaperRowNames();
  std::vector<std::string> methods = {"pd-lbfgs", "newton-pcg", "newton-cholesky"};
  std::string masses = "equal-nodes";
  std::string optimizer = "lbfgsb";
  TableOptions options;
  std::string json_file;
  bool resume = false;
  std::string markdown_file;
  std::string plot_file;
  bool small = false;
  bool report = false;
};

void WriteFileAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw InvalidInputError("cannot write '" + tmp + "'");
    out << text;
    if (!out) throw InvalidInputError("cannot write '" + tmp + "'");
  }
  std::filesystem::rename(tmp, path);
}

std::string Joined(const std::vector<std::string>& items) {
  std::string s;
  for (const std::string& i : items) s += (s.empty() ? "" : ",") + i;
  return s;
}

std::string CommandLine(const TableArgs& a) {
  if (a.report) return "diffpd table --report --json " + a.json_file;
  std::ostringstream s;
  s << "diffpd table --rows " << Joined(a.rows) << " --methods " << Joined(a.methods) << " --threads "
    << a.options.threads << " --evaluations " << a.options.evaluations << " --newton-evaluations "
    << a.options.newton_evaluations << " --draws " << a.options.random_draws << " --masses " << a.masses;
  if (a.small) s << " --small";
  if (a.options.optimise) s << " --optimise --optimizer " << a.optimizer;
  if (a.options.optimiser_evaluations > 0) s << " --optimiser-evaluations " << a.options.optimiser_evaluations;
  if (a.options.optimiser_minutes > 0) s << " --optimiser-minutes " << a.options.optimiser_minutes;
  if (a.options.budget_minutes > 0) s << " --budget-minutes " << a.options.budget_minutes;
  if (!a.json_file.empty()) s << " --json " << a.json_file;
  if (a.resume) s << " --resume";
  return s.str();
}

int RunTableArgs(const TableArgs& args) {
  TableOptions options = args.options;
  options.rows = args.rows;
  options.methods = ParseMethods(args.methods);
  options.masses = ParseMassLumping(args.masses);
  options.optimizer = ParseRowOptimizer(args.optimizer);
  options.size = args.small ? RowSize::kSmall : RowSize::kPaper;
  std::unique_ptr<TableResult> previous;
  if (args.report) {
    options.measure = false;
    if (args.json_file.empty()) throw InvalidInputError("--report needs --json FILE (the result to report)");
  }
  if (args.resume || args.report) {
    if (args.json_file.empty()) throw InvalidInputError("--resume needs --json FILE (the file to resume from)");
    std::ifstream in(args.json_file);
    if (!in) throw InvalidInputError("--resume: cannot open '" + args.json_file + "'");
    nlohmann::json j;
    try {
      in >> j;
    } catch (const nlohmann::json::exception& e) {
      throw InvalidInputError("--resume: '" + args.json_file + "' is not JSON: " + e.what());
    }
    previous = std::make_unique<TableResult>(TableFromJson(j));
  }
  auto checkpoint = [&](const TableResult& r) {
    if (!args.json_file.empty() && !args.report) WriteFileAtomically(args.json_file, TableToJson(r).dump(2) + "\n");
  };
  TableResult result = RunTable(options, previous.get(), checkpoint, &std::cerr);
  checkpoint(result);
  std::stable_sort(result.rows.begin(), result.rows.end(),
                   [](const TableRowResult& a, const TableRowResult& b) { return a.table_index < b.table_index; });
  PrintTable(result, stdout);
  if (!args.markdown_file.empty()) WriteFileAtomically(args.markdown_file, TableMarkdown(result, CommandLine(args)));
  if (!args.plot_file.empty()) WriteTablePlot(result, args.plot_file);
  return 0;
}

// The arguments joined by spaces, those with characters a shell treats
// specially single-quoted.
std::string ShellLine(const std::vector<std::string>& argv) {
  std::string line;
  for (const std::string& a : argv) {
    const bool plain = !a.empty() && a.find_first_not_of(
                                         "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                         "0123456789_./,=:+-@%") == std::string::npos;
    std::string quoted = "'";
    for (char c : a) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    quoted += "'";
    line += (line.empty() ? "" : " ") + (plain ? a : quoted);
  }
  return line;
}

}  // namespace

Subcommand AddTableCommand(CLI::App* parent, const std::vector<std::string>& argv) {
  auto args = std::make_shared<TableArgs>();
  args->options.command = ShellLine(argv);
  CLI::App* cmd =
      parent->add_subcommand("table", "the DiffPD paper's table (rows 1-11) measured here, beside the paper's numbers");
  cmd->footer(kTableFooter);
  cmd->add_option("--rows", args->rows, "comma-separated rows, in the order to run them")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--methods", args->methods,
                  "comma-separated methods: pd-lbfgs, pd, newton-cholesky, newton-pcg, newton-ldlt (the paper's "
                  "Newton: simplicial LDL^T under AMD)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--masses", args->masses,
                  "equal-nodes (the original code's rho dx^3 on every node: the paper's problems) or lumped (this "
                  "library's masses)")
      ->capture_default_str();
  cmd->add_option("--threads", args->options.threads, "threads of every solve (0: OpenMP default)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--budget-minutes", args->options.budget_minutes,
                  "stop before the next evaluation after this many minutes (0: no budget)")
      ->capture_default_str();
  cmd->add_option("--draws", args->options.random_draws,
                  "random draws (of each row's 16, the normalisation) to evaluate in this run; fewer leave the row "
                  "for a later --resume")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--evaluations", args->options.evaluations, "evaluations per PD method (mean)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--newton-evaluations", args->options.newton_evaluations, "evaluations per Newton method (mean)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("--optimise", args->options.optimise,
                "then optimise every optimised row with each PD method (--optimizer, the row's bounds and evaluation "
                "budget); Newton methods stay timed at x_init");
  cmd->add_option("--optimizer", args->optimizer,
                  "the optimiser of --optimise: lbfgsb (L-BFGS-B, the paper's) or ipopt (limited-memory Hessian)")
      ->capture_default_str();
  cmd->add_option("--optimiser-evaluations", args->options.optimiser_evaluations,
                  "loss evaluations per optimisation (0: the row's budget)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--optimiser-minutes", args->options.optimiser_minutes,
                  "wall-clock minutes per optimisation; it stops at its next iteration (0: none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--json", args->json_file, "JSON file of the result, rewritten after every draw and method");
  cmd->add_flag("--resume", args->resume, "read --json FILE back and skip the rows and methods it has finished");
  cmd->add_option("--markdown", args->markdown_file, "write the table as Markdown to this file");
  cmd->add_option("--plot", args->plot_file, "write a PNG chart of seconds per evaluation (needs gnuplot)");
  cmd->add_flag("--small", args->small, "the reduced instances (seconds per row)");
  cmd->add_flag("--report", args->report, "measure nothing: print (and --markdown, --plot) the result in --json FILE")
      ->excludes("--resume");
  return {cmd, [args] { return RunTableArgs(*args); }};
}

}  // namespace diffpd::problems
