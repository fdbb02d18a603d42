// Benchmark (not a test): one solve of the PD factor, three right-hand sides,
// by CHOLMOD and by its blocked copy (solver/parallel_triangular_solve.h) on
// 1 and 2 threads, on the node grids of the cantilever at 1x, 2x, 4x and 8x
// its element count (27-point stencil: the PD matrix's pattern; nested
// dissection; the layout PdSystem uses at that size), and with --large at
// 64x (140 481 nodes, supernodal). The three solves alternate within each
// repetition; times are medians.
// Usage: solve_benchmark [--large] [--json]
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/cholmod_solver.h"
#include "solver/grid_matrices.h"

namespace diffpd::internal {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double Median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

struct Grid {
  const char* name;
  int nx, ny, nz;
};

nlohmann::json Measure(const Grid& grid) {
  const SparseMatrix a = HexGridMatrix(grid.nx, grid.ny, grid.nz, 0.5);
  const int n = static_cast<int>(a.rows());
  // PdSystem's choice of layout (solver/pd_system.cc): simplicial up to 20 000 nodes.
  const CholmodLayout layout = n <= 20000 ? CholmodLayout::kSimplicial : CholmodLayout::kSupernodal;
  CholmodSolver cholmod(layout, CholmodOrdering::kNestedDissection);
  CholmodSolver one(layout, CholmodOrdering::kNestedDissection, CholmodSolveKernel::kParallelCopy);
  CholmodSolver two(layout, CholmodOrdering::kNestedDissection, CholmodSolveKernel::kParallelCopy);
  two.set_solve_threads(2);
  Clock::time_point t0 = Clock::now();
  cholmod.Factorize(a);
  const double factor_s = Seconds(t0);
  one.Factorize(a);
  t0 = Clock::now();
  two.Factorize(a);
  const double factor_and_copy_s = Seconds(t0);
  const MatrixXd b = MatrixXd::Random(n, 3);
  const int repeat = n > 100000 ? 11 : 101;
  std::vector<double> t_cholmod, t_one, t_two;
  MatrixXd x_cholmod, x_two;
  for (int r = 0; r < repeat; ++r) {
    t0 = Clock::now();
    x_cholmod = cholmod.Solve(b);
    t_cholmod.push_back(Seconds(t0));
    t0 = Clock::now();
    one.Solve(b);
    t_one.push_back(Seconds(t0));
    t0 = Clock::now();
    x_two = two.Solve(b);
    t_two.push_back(Seconds(t0));
  }
  const double ms_cholmod = 1e3 * Median(t_cholmod), ms_two = 1e3 * Median(t_two);
  return {{"grid", grid.name},
          {"nodes", n},
          {"layout", layout == CholmodLayout::kSimplicial ? "simplicial" : "supernodal"},
          {"factor_entries", cholmod.factor_nonzeros()},
          {"factorization_s", factor_s},
          {"factorization_and_copy_s", factor_and_copy_s},
          {"cholmod_ms", ms_cholmod},
          {"copy_1_thread_ms", 1e3 * Median(t_one)},
          {"copy_2_threads_ms", ms_two},
          {"speedup_2_threads", ms_cholmod / ms_two},
          {"serial_fraction", two.parallel_copy() ? two.parallel_copy()->serial_fraction() : 1.0},
          {"copy_mib", two.parallel_copy() ? two.parallel_copy()->bytes() / 1048576.0 : 0.0},
          {"rel_difference", (x_two - x_cholmod).norm() / x_cholmod.norm()}};
}

int Main(int argc, char** argv) {
  bool large = false, json = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--large"))
      large = true;
    else if (!std::strcmp(argv[i], "--json"))
      json = true;
    else {
      std::fprintf(stderr, "usage: solve_benchmark [--large] [--json]\n");
      return 2;
    }
  }
  std::vector<Grid> grids = {{"1x", 33, 9, 9}, {"2x", 65, 9, 9}, {"4x", 65, 17, 9}, {"8x", 65, 17, 17}};
  if (large) grids.push_back({"64x", 129, 33, 33});
  nlohmann::json rows = nlohmann::json::array();
  if (!json)
    std::printf("%-4s %8s %11s %10s %10s %10s %10s %8s %7s %9s %9s\n", "grid", "nodes", "L entries", "cholmod ms",
                "copy 1t ms", "copy 2t ms", "2t speedup", "serial", "fact s", "+copy s", "copy MiB");
  for (const Grid& g : grids) {
    const nlohmann::json row = Measure(g);
    rows.push_back(row);
    if (!json)
      std::printf("%-4s %8d %11.0f %10.3f %10.3f %10.3f %10.2f %8.3f %7.3f %9.3f %9.1f\n", g.name,
                  row["nodes"].get<int>(), row["factor_entries"].get<double>(), row["cholmod_ms"].get<double>(),
                  row["copy_1_thread_ms"].get<double>(), row["copy_2_threads_ms"].get<double>(),
                  row["speedup_2_threads"].get<double>(), row["serial_fraction"].get<double>(),
                  row["factorization_s"].get<double>(), row["factorization_and_copy_s"].get<double>(),
                  row["copy_mib"].get<double>());
  }
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  if (json)
    std::cout << rows.dump(1) << "\n";
  else
    std::printf("peak RSS %.0f MiB (three factors of the largest grid and a copy each of two)\n",
                usage.ru_maxrss / 1024.0);
  return 0;
}

}  // namespace
}  // namespace diffpd::internal

int main(int argc, char** argv) { return diffpd::internal::Main(argc, argv); }
