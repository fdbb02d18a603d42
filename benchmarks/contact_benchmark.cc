// Benchmark (not a test): what frictional contact costs.
//  1. The PD matrix with an active set of s nodes erased: Woodbury update on
//     the existing factor vs refactorisation, as s grows (a 24 x 24 x 4 hex
//     block, 9375 DoFs, the s nodes spread over its 625-node bottom face): time to
//     prepare a new set (cold: no cached columns; warm: one node changed) and
//     time per solve (three axes).
//  2. Whole rollouts: rolling-sphere forward and backward with either path.
//  3. The cantilever with and without an inactive contact plane declared.
// Usage: contact_benchmark [--quick] [matrix] [cantilever] [sphere] (default:
// all three parts). Prints plain tables; times are medians.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

#include "scenes/cantilever_plane.h"
#include "diffpd/box_mesh.h"
#include "diffpd/simulator.h"
#include "fem/fem_model.h"
#include "scenes/rolling_sphere.h"
#include "solver/pd_system.h"

namespace diffpd {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

template <class F>
double Median(int repeat, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < repeat; ++r) t.push_back(f());
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

void LinearAlgebra(bool quick) {
  const int nx = 24, nz = 4;
  const Mesh mesh = MakeBoxHexMesh(Eigen::Vector3i(nx, nx, nz), Vec3(0.24, 0.24, 0.04));
  internal::FemModel fem(mesh);
  const std::vector<char> fixed(mesh.num_dofs(), 0);
  std::vector<int> bottom;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.vertices(2, i) < 1e-9) bottom.push_back(i);
  const double h = 0.01, rho = 1e3, w = 2e6;
  std::printf("\n# PD matrix with s contact nodes erased: %d nodes, %d DoFs (ms)\n", mesh.num_vertices(),
              mesh.num_dofs());
  std::printf("%6s %12s %12s %12s | %12s %12s %12s | %14s %14s\n", "s", "refactor", "wood_cold", "wood_1new",
              "solve_base", "solve_refac", "solve_wood", "step20_refac", "step20_wood");
  internal::PdSystem base(fem, fixed);
  base.Update(h, rho, w);
  const VectorXd r = VectorXd::Random(mesh.num_dofs());
  const int repeat = quick ? 3 : 7;
  const double solve_base = 1e3 * Median(repeat, [&] {
                              const auto t0 = Clock::now();
                              base.Solve(r);
                              return Seconds(t0);
                            });
  for (const int s : {4, 16, 64, 256, 400}) {
    if (quick && s > 256) break;
    // s nodes spread over the bottom face; `shift` gives a different set of the same size.
    auto set = [&](int shift) {
      std::vector<int> nodes;
      for (int k = 0; k < s; ++k)
        nodes.push_back(bottom[(static_cast<size_t>(k) * bottom.size() / s + shift) % bottom.size()]);
      std::sort(nodes.begin(), nodes.end());
      nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
      return nodes;
    };
    int shift = 0;
    internal::PdSystem refac(fem, fixed);
    refac.Update(h, rho, w);
    const double t_refac = 1e3 * Median(repeat, [&] {
                             const std::vector<int> nodes = set(++shift);
                             const auto t0 = Clock::now();
                             refac.SetActiveNodes(nodes, ContactLinearSolve::kRefactorize);
                             return Seconds(t0);
                           });
    const double solve_refac = 1e3 * Median(repeat, [&] {
                                 const auto t0 = Clock::now();
                                 refac.Solve(r);
                                 return Seconds(t0);
                               });
    const double t_cold = 1e3 * Median(repeat, [&] {
                            internal::PdSystem wood(fem, fixed);
                            wood.Update(h, rho, w);
                            const std::vector<int> nodes = set(++shift);
                            const auto t0 = Clock::now();
                            wood.SetActiveNodes(nodes, ContactLinearSolve::kWoodbury);
                            return Seconds(t0);
                          });
    internal::PdSystem wood(fem, fixed);
    wood.Update(h, rho, w);
    std::vector<int> nodes = set(0);
    wood.SetActiveNodes(nodes, ContactLinearSolve::kWoodbury);
    const double t_warm =
        1e3 * Median(repeat, [&] {
          // One node replaced by a neighbour not seen before: one new column.
          std::vector<int> next = nodes;
          next[next.size() / 2] =
              bottom[(std::find(bottom.begin(), bottom.end(), next[next.size() / 2]) - bottom.begin() + 1 + shift++) %
                     bottom.size()];
          std::sort(next.begin(), next.end());
          next.erase(std::unique(next.begin(), next.end()), next.end());
          const auto t0 = Clock::now();
          wood.SetActiveNodes(next, ContactLinearSolve::kWoodbury);
          return Seconds(t0);
        });
    const double solve_wood = 1e3 * Median(repeat, [&] {
                                const auto t0 = Clock::now();
                                wood.Solve(r);
                                return Seconds(t0);
                              });
    // A step of 20 PD iterations whose active set changed once (warm Woodbury).
    std::printf("%6d %12.3f %12.3f %12.3f | %12.3f %12.3f %12.3f | %14.3f %14.3f\n", s, t_refac, t_cold, t_warm,
                solve_base, solve_refac, solve_wood, t_refac + 20 * solve_refac, t_warm + 20 * solve_wood);
  }
}

struct RolloutTiming {
  double forward = 0, backward = 0;
  double passes = 0, contact = 0;
  int factorizations = 0;
};

RolloutTiming TimeRollingSphere(ContactLinearSolve solve, Method method, int steps, bool backward) {
  const problems::RollingSphere problem(solve);
  SolverOptions options;
  options.method = method;
  options.time_step = problem.default_time_step();
  options.rel_tolerance = 1e-6;
  options.max_iterations = 20000;
  options.backward_rel_tolerance = 1e-8;
  Simulator sim(problem.MakeScene(), options);
  RolloutTiming t;
  auto t0 = Clock::now();
  const Rollout r = sim.Simulate(problem.InitialState(sim), std::vector<StepInput>(steps));
  t.forward = Seconds(t0);
  for (const auto& rep : r.reports) {
    t.passes += rep.active_set_passes / double(steps);
    t.contact += rep.contact_nodes.size() / double(steps);
  }
  if (backward) {
    LossGradient dl(steps);
    dl.dx[steps] = VectorXd::Ones(sim.num_dofs());
    t0 = Clock::now();
    sim.Backward(r, dl);
    t.backward = Seconds(t0);
  }
  t.factorizations = sim.num_pd_factorizations();
  return t;
}

void RollingSphere(bool quick) {
  const int steps = quick ? 10 : 100;
  std::printf("\n# rolling-sphere, %d steps, rel_tolerance 1e-6 (s; passes and contact nodes per step)\n", steps);
  std::printf("%-10s %-12s %10s %10s %8s %10s\n", "method", "pd_solve", "forward", "backward", "passes", "contacts");
  for (const Method m : {Method::kPdLbfgs, Method::kPd}) {
    for (const ContactLinearSolve s : {ContactLinearSolve::kWoodbury, ContactLinearSolve::kRefactorize}) {
      const RolloutTiming t = TimeRollingSphere(s, m, m == Method::kPd ? std::min(steps, 10) : steps, true);
      std::printf("%-10s %-12s %10.3f %10.3f %8.2f %10.1f\n", ToString(m),
                  s == ContactLinearSolve::kWoodbury ? "woodbury" : "refactorize", t.forward, t.backward, t.passes,
                  t.contact);
    }
  }
  const RolloutTiming newton = TimeRollingSphere(ContactLinearSolve::kWoodbury, Method::kNewtonCholesky, steps, true);
  std::printf("%-10s %-12s %10.3f %10.3f %8.2f %10.1f\n", "newton-ch", "-", newton.forward, newton.backward,
              newton.passes, newton.contact);
}

void CantileverPlane(bool quick) {
  const int steps = 5, repeat = quick ? 3 : 5;
  std::printf("\n# cantilever (8019 DoFs), %d steps: forward seconds per step with and without an inactive plane\n",
              steps);
  std::printf("%-16s %14s %14s %10s\n", "method", "no_plane", "inactive_plane", "overhead");
  for (const Method m : {Method::kPdLbfgs, Method::kNewtonCholesky}) {
    SolverOptions options;
    options.method = m;
    options.rel_tolerance = 1e-4;
    const problems::Cantilever plain;
    const problems::CantileverWithPlane plane;
    Simulator sim_plain(plain.MakeScene(), options), sim_plane(plane.MakeScene(), options);
    const State init = plain.InitialState(sim_plain);
    sim_plain.Step(init, StepInput());  // factorisations outside the timing
    sim_plane.Step(init, StepInput());
    // Interleaved runs, so that load changes on the machine hit both alike.
    std::vector<double> t[2];
    for (int r = 0; r < repeat; ++r)
      for (int with = 0; with < 2; ++with) {
        const auto t0 = Clock::now();
        (with ? sim_plane : sim_plain).Simulate(init, std::vector<StepInput>(steps));
        t[with].push_back(Seconds(t0) / steps);
      }
    for (auto& v : t) std::sort(v.begin(), v.end());
    const double a = t[0][repeat / 2], b = t[1][repeat / 2];
    std::printf("%-16s %14.4f %14.4f %9.1f%%\n", ToString(m), a, b, 100 * (b / a - 1));
  }
}

}  // namespace
}  // namespace diffpd

int main(int argc, char** argv) {
  bool quick = false, matrix = false, cantilever = false, sphere = false;
  for (int a = 1; a < argc; ++a) {
    quick = quick || std::strcmp(argv[a], "--quick") == 0;
    matrix = matrix || std::strcmp(argv[a], "matrix") == 0;
    cantilever = cantilever || std::strcmp(argv[a], "cantilever") == 0;
    sphere = sphere || std::strcmp(argv[a], "sphere") == 0;
  }
  if (!matrix && !cantilever && !sphere) matrix = cantilever = sphere = true;
  if (matrix) diffpd::LinearAlgebra(quick);
  if (cantilever) diffpd::CantileverPlane(quick);
  if (sphere) diffpd::RollingSphere(quick);
  return 0;
}
