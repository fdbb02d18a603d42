// `diffpd run`: simulates a problem, prints a per-step table, writes VTK
// frames and a summary.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "diffpd/simulator.h"
#include "diffpd/vtk_writer.h"
#include "problem_registry.h"

namespace diffpd::problems {

int RunCommand(const CommandArgs& args) {
  const auto problem = MakeProblem(args.problem);
  const int steps = args.steps > 0 ? args.steps : problem->default_steps();
  const SolverOptions options = OptionsFromArgs(args, problem->default_time_step(), 1e-4);
  Simulator sim(problem->MakeScene(), options);
  State state = problem->InitialState(sim);
  const std::vector<StepInput> inputs = problem->Inputs(sim, steps);
  const Mesh& mesh = sim.scene().mesh;
  const VectorXd mass = sim.LumpedMass();
  const VectorXd rest = sim.RestState().x;

  std::unique_ptr<PvdWriter> pvd;
  if (!args.out_dir.empty()) {
    pvd = std::make_unique<PvdWriter>(args.out_dir, problem->name());
    pvd->AddFrame(0.0, mesh, Eigen::Map<const Eigen::Matrix3Xd>(state.x.data(), 3, mesh.num_vertices()));
  }
  FILE* table = args.json ? stderr : stdout;
  std::fprintf(table, "# %s: %d nodes, %d elements, %d DoFs, method %s, h = %g s, %d steps\n", problem->name().c_str(),
               mesh.num_vertices(), mesh.num_elements(), sim.num_dofs(), ToString(options.method), options.time_step,
               steps);
  std::fprintf(table, "%6s %8s %12s %12s %12s %14s %14s\n", "step", "iters", "|grad g|0", "|grad g|", "time_ms",
               "max_disp_m", "kinetic_J");
  nlohmann::json step_rows = nlohmann::json::array();
  double total_seconds = 0;
  long total_iterations = 0;
  for (int i = 0; i < steps; ++i) {
    StepReport rep;
    state = sim.Step(state, inputs[i], &rep);
    total_seconds += rep.seconds;
    total_iterations += rep.iterations;
    double max_disp = 0;
    for (int v = 0; v < mesh.num_vertices(); ++v)
      max_disp = std::max(max_disp, (state.x.segment<3>(3 * v) - rest.segment<3>(3 * v)).norm());
    const double kinetic = 0.5 * state.v.cwiseProduct(mass).dot(state.v);
    std::fprintf(table, "%6d %8d %12.4e %12.4e %12.3f %14.6e %14.6e\n", i + 1, rep.iterations, rep.initial_residual,
                 rep.final_residual, 1e3 * rep.seconds, max_disp, kinetic);
    std::fflush(table);
    step_rows.push_back({{"step", i + 1},
                         {"iterations", rep.iterations},
                         {"line_search_steps", rep.line_search_steps},
                         {"residual", rep.final_residual},
                         {"seconds", rep.seconds},
                         {"max_displacement", max_disp},
                         {"kinetic_energy", kinetic}});
    if (pvd)
      pvd->AddFrame((i + 1) * options.time_step, mesh,
                    Eigen::Map<const Eigen::Matrix3Xd>(state.x.data(), 3, mesh.num_vertices()));
  }
  nlohmann::json summary = {{"problem", problem->name()},
                            {"method", ToString(options.method)},
                            {"dofs", sim.num_dofs()},
                            {"steps", steps},
                            {"time_step", options.time_step},
                            {"forward_s", total_seconds},
                            {"iterations_per_step", double(total_iterations) / std::max(steps, 1)},
                            {"pd_factorizations", sim.num_pd_factorizations()},
                            {"step_table", step_rows}};
  std::fprintf(table, "# total %.3f s, %.2f iterations per step\n", total_seconds,
               double(total_iterations) / std::max(steps, 1));
  if (pvd) {
    pvd->Write();
    std::ofstream(std::filesystem::path(args.out_dir) / "summary.json") << summary.dump(2) << "\n";
    std::fprintf(table, "# wrote %d VTK frames and summary.json to %s\n", pvd->num_frames(), args.out_dir.c_str());
  }
  if (args.json) std::printf("%s\n", summary.dump(2).c_str());
  return 0;
}

}  // namespace diffpd::problems
