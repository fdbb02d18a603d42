// diffpd-mpi: problems that are sums of independent rollouts, the rollouts
// spread over MPI ranks (DistributedRolloutSet). Rank 0 runs the optimiser;
// the other ranks simulate and differentiate their terms.
//
//   mpirun -np 2 diffpd-mpi calibrate-plant --recordings 4 --threads 1 [--json]
//   mpirun -np 2 diffpd-mpi calibrate-starfish [--recordings FILE...] [--start S] [--seconds S] [--json]
//   mpirun -np 2 diffpd-mpi train-starfish --starts 4 [--small] [--evaluations K] [--json]
//   srun -n 8 diffpd-mpi calibrate-plant --recordings 16        (slurm)
//
// calibrate-plant fits the plant's E and nu to synthetic recordings
// (plant_recordings.h) by Levenberg-Marquardt; calibrate-starfish fits the
// starfish's material and tendon actuation to a window of each of several
// real recordings (starfish_recordings_fit.h; default the shared cyclic1 and
// cyclic2) by Levenberg-Marquardt; train-starfish trains the
// starfish's controller over several initial states (swimmer_starts.h) with
// Adam, L-BFGS or Ipopt. Prints the iteration table or learning curve and a report
// on rank 0's stderr; --json prints the report as one JSON object on stdout,
// its "run" member holding what depends on the run (ranks, threads, seconds)
// and the rest what the computation gave (equal on any number of ranks).
// Exit status: 0 usable fit / raised reward, 5 otherwise, 2 bad input (with
// "diffpd-mpi: error: <message>" on rank 0's stderr).
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "calibration/calibrate_plant.h"
#include "calibration/plant_recordings.h"
#include "calibration/rollout_set_fit.h"
#include "calibration/starfish_recordings_fit.h"
#include "control/starfish_control.h"
#include "control/swimmer_starts.h"
#include "diffpd/error.h"
#include "diffpd/solvers/mpi/distributed_rollout_set.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

struct Arguments {
  std::string problem;
  int recordings = 4;
  std::string method = "pd-lbfgs";
  int threads = 1;
  int max_iterations = 25;
  bool json = false;
  // train-starfish
  int starts = 4;
  bool small = false;
  int steps = 0;  // 0: the instance's
  int evaluations = 100;
  std::string optimizer = "adam";
  double speed = SwimmerStartsOptions().speed;
  std::uint64_t seed = 42;
  std::string adjoint_solver;  // "": the command's (train-starfish iterative, calibrate-starfish direct)
  // calibrate-starfish
  std::vector<std::string> recording_files;  // empty: the shared cyclic1 and cyclic2
  double start = StarfishRecordingsOptions().start;
  double seconds = StarfishRecordingsOptions().seconds;
  int substeps = 2;
  int starfish_iterations = 10;
};

nlohmann::json Report(const Arguments& args, const solvers::DistributedRolloutSet& set, const RolloutSetFit& fit,
                      double setup_seconds) {
  const MaterialParameters truth = PlantCalibration().truth();
  const double e = fit.values[0], nu = fit.values[1];
  return {{"problem", args.problem},
          {"recordings", args.recordings},
          {"method", args.method},
          {"youngs_modulus", e},
          {"poissons_ratio", nu},
          {"truth", {{"youngs_modulus", truth.youngs_modulus}, {"poissons_ratio", truth.poissons_ratio}}},
          {"youngs_modulus_rel_error", std::abs(e - truth.youngs_modulus) / truth.youngs_modulus},
          {"poissons_ratio_rel_error", std::abs(nu - truth.poissons_ratio) / truth.poissons_ratio},
          {"initial_cost", fit.initial_cost},
          {"final_cost", fit.final_cost},
          {"iterations", fit.iterations},
          {"evaluations", fit.evaluations},
          {"usable", fit.usable},
          {"termination", fit.termination},
          {"run",
           {{"ranks", set.size()},
            {"threads_per_rank", args.threads},
            {"fit_seconds", fit.seconds},
            {"seconds_per_evaluation", fit.evaluations > 0 ? fit.seconds / fit.evaluations : 0.0},
            {"setup_seconds", setup_seconds}}}};
}

int CalibratePlant(const Arguments& args) {
  const auto begin = std::chrono::steady_clock::now();
  PlantRecordingsOptions options;
  options.count = args.recordings;
  options.method = ParseMethod(args.method);
  options.threads = args.threads;
  solvers::DistributedRolloutSet set(MPI_COMM_WORLD, args.recordings, solvers::TermObjective::kLeastSquares,
                                     [&](int i) { return PlantRecordingTerm(i, options); });
  const double setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  if (!set.is_root()) {
    set.Serve();
    return 0;
  }
  std::fprintf(stderr, "# %s: %d recordings on %d ranks (%d thread(s) each), %s; set-up %.2f s\n", args.problem.c_str(),
               args.recordings, set.size(), args.threads, args.method.c_str(), setup_seconds);
  const RolloutSetFit fit = FitMaterialOverSet(&set, PlantCalibration().fitted(), args.max_iterations, stderr);
  set.Stop();
  const nlohmann::json report = Report(args, set, fit, setup_seconds);
  if (args.json) {
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    std::fprintf(stderr, "# E = %.6g Pa (truth %.6g), nu = %.6g (truth %.6g); cost %.4e -> %.4e\n", fit.values[0],
                 report["truth"]["youngs_modulus"].get<double>(), fit.values[1],
                 report["truth"]["poissons_ratio"].get<double>(), fit.initial_cost, fit.final_cost);
    std::fprintf(stderr, "# %d evaluations in %.3f s (%.4f s each); %s\n", fit.evaluations, fit.seconds,
                 report["run"]["seconds_per_evaluation"].get<double>(), fit.termination.c_str());
  }
  if (!fit.usable) std::fprintf(stderr, "diffpd-mpi: the fit is not usable: %s\n", fit.termination.c_str());
  return fit.usable ? 0 : 5;
}

nlohmann::json TrainingReport(const Arguments& args, const solvers::DistributedRolloutSet& set,
                              const MultiStartTraining& training, double setup_seconds) {
  nlohmann::json curve = nlohmann::json::array();
  for (const TrainingEvaluation& e : training.history) curve.push_back({e.simulated_steps, e.reward});
  int with_gradient = 0;
  double forward = 0, backward = 0;
  for (const TrainingEvaluation& e : training.history)
    if (e.backward_seconds > 0) {
      ++with_gradient;
      forward += e.forward_seconds;
      backward += e.backward_seconds;
    }
  return {{"problem", args.problem},
          {"starts", training.starts},
          {"start_speed", args.speed},
          {"small", args.small},
          {"steps_per_start", training.steps_per_start},
          {"method", args.method},
          {"adjoint_solver", args.adjoint_solver.empty() ? "iterative" : args.adjoint_solver},
          {"optimizer", training.optimizer},
          {"optimizer_report", training.optimizer_report},
          {"seed", args.seed},
          {"parameters", training.parameters},
          {"evaluations", static_cast<int>(training.history.size()) - 1},
          {"failed_evaluations", training.failed_evaluations},
          {"initial_reward", training.initial_reward()},
          {"final_reward", training.final_reward()},
          {"initial_start_rewards", training.initial_start_rewards},
          {"final_start_rewards", training.final_start_rewards},
          {"final_parameters_norm", training.final_parameters.norm()},
          {"learning_curve", curve},
          {"run",
           {{"ranks", set.size()},
            {"threads_per_rank", args.threads},
            {"training_seconds", training.total_seconds},
            // rank 0's own terms only
            {"rank0_forward_seconds_per_evaluation", with_gradient ? forward / with_gradient : 0.0},
            {"rank0_backward_seconds_per_evaluation", with_gradient ? backward / with_gradient : 0.0},
            {"setup_seconds", setup_seconds}}}};
}

int TrainStarfish(const Arguments& args) {
  const auto begin = Clock::now();
  Swimmer swimmer = StarfishControl().MakeSwimmer(args.small);
  if (args.steps > 0) swimmer.steps = args.steps;
  SolverOptions options = StarfishControl().BaseOptions(args.small);
  options.method = ParseMethod(args.method);
  options.num_threads = args.threads;
  // Explicit (kAuto's choices depend on what each rank's simulator solved before, which the layout changes).
  options.adjoint_solver = ParseAdjointSolver(args.adjoint_solver.empty() ? "iterative" : args.adjoint_solver);
  SwimmerStartsOptions starts;
  starts.count = args.starts;
  starts.speed = args.speed;
  starts.Validate();
  TrainingSettings settings;
  settings.evaluations = args.evaluations;
  settings.optimizer = ParseControlOptimizer(args.optimizer);
  CheckSetOptimizer(settings.optimizer);  // on every rank, before the collective set-up
  settings.log = stderr;
  solvers::DistributedRolloutSet set(MPI_COMM_WORLD, args.starts, solvers::TermObjective::kSum,
                                     [&](int i) { return SwimmerStartTerm(swimmer, options, args.seed, i, starts); });
  const double setup_seconds = Seconds(begin);
  if (!set.is_root()) {
    set.Serve();
    return 0;
  }
  std::fprintf(stderr, "# %s: %d starts of %d steps on %d ranks (%d thread(s) each), %s, %s; set-up %.2f s\n",
               args.problem.c_str(), args.starts, swimmer.steps, set.size(), args.threads, args.method.c_str(),
               args.optimizer.c_str(), setup_seconds);
  std::fprintf(stderr, "# %5s %9s %14s %10s %10s %12s\n", "eval", "steps", "reward", "forward", "backward", "|grad|");
  MultiStartTraining training;
  try {
    training = TrainOverStarts(&set, swimmer.steps, settings);
  } catch (...) {
    set.Stop();
    throw;
  }
  set.Stop();
  const nlohmann::json report = TrainingReport(args, set, training, setup_seconds);
  if (args.json) {
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    std::fprintf(stderr, "# reward %.6f -> %.6f over %d starts; %.2f s\n", training.initial_reward(),
                 training.final_reward(), training.starts, training.total_seconds);
  }
  const bool raised = training.final_reward() > training.initial_reward();
  if (!raised) std::fprintf(stderr, "diffpd-mpi: the training did not raise the reward\n");
  return raised ? 0 : 5;
}

nlohmann::json StarfishReport(const Arguments& args, const std::vector<std::string>& files,
                              const solvers::DistributedRolloutSet& set, const StarfishRecordingsFit& r,
                              const std::string& adjoint_solver, double setup_seconds) {
  const StarfishFit& fit = r.fit;
  return {{"problem", args.problem},
          {"recordings", files},
          {"window_start", args.start},
          {"window_seconds", args.seconds},
          {"substeps", args.substeps},
          {"rows", set.num_rows()},
          {"method", args.method},
          {"adjoint_solver", adjoint_solver},
          {"youngs_modulus", fit.material.youngs_modulus},
          {"poissons_ratio", fit.material.poissons_ratio},
          {"tendon_slack", fit.actuation.slack},
          {"tendon_lag", fit.actuation.lag},
          {"tendon_length", fit.actuation.length},
          {"initial_cost", fit.initial_cost},
          {"final_cost", fit.final_cost},
          {"initial_recording_costs", r.initial_costs},
          {"final_recording_costs", r.final_costs},
          {"iterations", fit.iterations},
          {"evaluations", r.evaluations},
          {"usable", fit.usable},
          {"termination", fit.termination},
          {"run",
           {{"ranks", set.size()},
            {"threads_per_rank", args.threads},
            {"fit_seconds", r.seconds},
            {"seconds_per_evaluation", r.evaluations > 0 ? r.seconds / r.evaluations : 0.0},
            {"setup_seconds", setup_seconds}}}};
}

int CalibrateStarfish(const Arguments& args) {
  const auto begin = Clock::now();
  std::vector<std::string> files = args.recording_files;
  if (files.empty())
    files = {SharedDataPath("starfish/data_horizontal_cyclic1.csv"),
             SharedDataPath("starfish/data_horizontal_cyclic2.csv")};
  StarfishCalibration problem;
  problem.set_substeps(args.substeps);
  SolverOptions options = problem.Options(ParseMethod(args.method), args.threads);
  // Explicit (kAuto's choices depend on each rank's earlier solves); the Jacobians' 5 tangents share a factorisation.
  const std::string adjoint_solver = args.adjoint_solver.empty() ? "direct" : args.adjoint_solver;
  options.adjoint_solver = ParseAdjointSolver(adjoint_solver);
  StarfishRecordingsOptions recordings;
  recordings.start = args.start;
  recordings.seconds = args.seconds;
  solvers::DistributedRolloutSet set(
      MPI_COMM_WORLD, static_cast<int>(files.size()), solvers::TermObjective::kLeastSquares,
      [&](int i) { return StarfishRecordingTerm(problem, files[i], options, recordings); });
  const double setup_seconds = Seconds(begin);
  if (!set.is_root()) {
    set.Serve();
    return 0;
  }
  std::fprintf(stderr,
               "# %s: %zu recordings ([%g s, %g s] each, %d rows) on %d ranks (%d thread(s) each), %s; set-up "
               "%.2f s\n",
               args.problem.c_str(), files.size(), args.start, args.start + args.seconds, set.num_rows(), set.size(),
               args.threads, args.method.c_str(), setup_seconds);
  StarfishRecordingsFit fit;
  try {
    fit = FitStarfishOverSet(&set, recordings.guess.density, args.starfish_iterations, stderr);
  } catch (...) {
    set.Stop();
    throw;
  }
  set.Stop();
  const nlohmann::json report = StarfishReport(args, files, set, fit, adjoint_solver, setup_seconds);
  if (args.json) {
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    std::fprintf(stderr,
                 "# E = %.6g Pa, nu = %.6g, tendon slack %.4f mm, lag %.4f s, length %.3f mm; cost %.4e -> %.4e\n",
                 fit.fit.material.youngs_modulus, fit.fit.material.poissons_ratio, fit.fit.actuation.slack * 1e3,
                 fit.fit.actuation.lag, fit.fit.actuation.length * 1e3, fit.fit.initial_cost, fit.fit.final_cost);
    std::fprintf(stderr, "# %d evaluations in %.3f s; %s\n", fit.evaluations, fit.seconds, fit.fit.termination.c_str());
  }
  if (!fit.fit.usable) std::fprintf(stderr, "diffpd-mpi: the fit is not usable: %s\n", fit.fit.termination.c_str());
  return fit.fit.usable ? 0 : 5;
}

int Run(const Arguments& args) {
  if (args.problem == "train-starfish") return TrainStarfish(args);
  if (args.problem == "calibrate-starfish") return CalibrateStarfish(args);
  return CalibratePlant(args);
}

}  // namespace
}  // namespace diffpd::problems

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  diffpd::problems::Arguments args;
  CLI::App app("sums of independent rollouts spread over MPI ranks (rank 0 runs the optimiser)", "diffpd-mpi");
  app.require_subcommand(1);
  CLI::App* plant = app.add_subcommand("calibrate-plant", "fit the plant's E and nu to several synthetic recordings");
  plant->add_option("--recordings", args.recordings, "recordings (each a rollout; spread over the ranks)")
      ->check(CLI::Range(1, 4096));
  plant->add_option("--max-iterations", args.max_iterations, "Levenberg-Marquardt iterations")
      ->check(CLI::Range(1, 10000));
  CLI::App* starfish =
      app.add_subcommand("train-starfish", "train the starfish's controller over several initial states");
  starfish->add_option("--starts", args.starts, "initial states (each a rollout; spread over the ranks)")
      ->check(CLI::Range(1, 4096));
  starfish->add_flag("--small", args.small, "the small instance (40 steps)");
  starfish->add_option("--steps", args.steps, "steps per rollout (default: the instance's, 200 or 40)")
      ->check(CLI::Range(1, 100000));
  starfish->add_option("--evaluations", args.evaluations, "evaluations of the whole set (Adam: epochs)")
      ->check(CLI::Range(1, 1000000));
  starfish->add_option("--optimizer", args.optimizer, "adam, lbfgs or ipopt");
  starfish->add_option("--speed", args.speed, "lateral speed of the starts 1.. (m/s)");
  starfish->add_option("--seed", args.seed, "the network's initialisation");
  starfish->add_option("--adjoint-solver", args.adjoint_solver,
                       "iterative or direct (fixed: results independent of timing)");
  CLI::App* starfish_fit = app.add_subcommand(
      "calibrate-starfish", "fit the starfish's material and tendon actuation to several recordings at once");
  starfish_fit->add_option("--recordings", args.recording_files,
                           "recording files (default: the shared cyclic1 and cyclic2; each a rollout)");
  starfish_fit->add_option("--start", args.start, "each window's start (s)");
  starfish_fit->add_option("--seconds", args.seconds, "each window's length (s)");
  starfish_fit->add_option("--substeps", args.substeps, "simulation steps per camera frame")->check(CLI::Range(1, 100));
  starfish_fit->add_option("--max-iterations", args.starfish_iterations, "Levenberg-Marquardt iterations")
      ->check(CLI::Range(0, 10000));
  starfish_fit->add_option("--adjoint-solver", args.adjoint_solver,
                           "direct (default) or iterative (fixed: results independent of timing)");
  for (CLI::App* sub : {plant, starfish, starfish_fit}) {
    sub->add_option("--method", args.method, "simulator method");
    sub->add_option("--threads", args.threads, "threads per rank")->check(CLI::Range(1, 64));
    sub->add_flag("--json", args.json, "print the report as JSON on stdout");
  }
  int status = 0;
  try {
    app.parse(argc, argv);
    args.problem = app.get_subcommands().front()->get_name();
    status = diffpd::problems::Run(args);
  } catch (const CLI::ParseError& e) {  // rank 0 prints the help or the error
    status = (rank == 0 ? app.exit(e) : e.get_exit_code()) == 0 ? 0 : 2;
  } catch (const std::exception& e) {
    if (rank == 0) std::fprintf(stderr, "diffpd-mpi: error: %s\n", e.what());
    status = 2;
  }
  MPI_Finalize();
  return status;
}
