// diffpd-mpi: calibrations over several recordings with the recordings
// spread over MPI ranks (DistributedRolloutSet). Rank 0 runs Ceres; the
// other ranks simulate and differentiate their recordings.
//
//   mpirun -np 2 diffpd-mpi calibrate-plant --recordings 4 --threads 1 [--json]
//   srun -n 8 diffpd-mpi calibrate-plant --recordings 16        (slurm)
//
// Prints the iteration table and a report (fitted E and nu against the
// truth, costs, evaluations, seconds) on rank 0; --json prints the report as
// one JSON object on stdout. Exit status: 0 usable fit, 5 unusable, 2 bad
// input (with "diffpd-mpi: error: <message>" on rank 0's stderr).
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "calibration/calibrate_plant.h"
#include "calibration/plant_recordings.h"
#include "calibration/rollout_set_fit.h"
#include "diffpd/error.h"
#include "diffpd/solvers/mpi/distributed_rollout_set.h"

namespace diffpd::problems {
namespace {

struct Arguments {
  std::string problem;
  int recordings = 4;
  std::string method = "pd-lbfgs";
  int threads = 1;
  int max_iterations = 25;
  bool json = false;
};

nlohmann::json Report(const Arguments& args, const solvers::DistributedRolloutSet& set, const RolloutSetFit& fit,
                      double setup_seconds) {
  const MaterialParameters truth = PlantCalibration().truth();
  const double e = fit.values[0], nu = fit.values[1];
  return {{"problem", args.problem},
          {"recordings", args.recordings},
          {"ranks", set.size()},
          {"threads_per_rank", args.threads},
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
          {"fit_seconds", fit.seconds},
          {"seconds_per_evaluation", fit.evaluations > 0 ? fit.seconds / fit.evaluations : 0.0},
          {"setup_seconds", setup_seconds},
          {"usable", fit.usable},
          {"termination", fit.termination}};
}

int Run(const Arguments& args, int rank) {
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
                 report["seconds_per_evaluation"].get<double>(), fit.termination.c_str());
  }
  if (!fit.usable) std::fprintf(stderr, "diffpd-mpi: the fit is not usable: %s\n", fit.termination.c_str());
  return fit.usable ? 0 : 5;
}

}  // namespace
}  // namespace diffpd::problems

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  diffpd::problems::Arguments args;
  CLI::App app("calibration over several recordings, spread over MPI ranks (rank 0 runs Ceres)", "diffpd-mpi");
  app.add_option("problem", args.problem, "calibrate-plant")->required()->check(CLI::IsMember({"calibrate-plant"}));
  app.add_option("--recordings", args.recordings, "recordings (each a rollout; spread over the ranks)")
      ->check(CLI::Range(1, 4096));
  app.add_option("--method", args.method, "simulator method of the fit");
  app.add_option("--threads", args.threads, "threads per rank")->check(CLI::Range(1, 64));
  app.add_option("--max-iterations", args.max_iterations, "Levenberg-Marquardt iterations")
      ->check(CLI::Range(1, 10000));
  app.add_flag("--json", args.json, "print the report as JSON on stdout");
  int status = 0;
  try {
    app.parse(argc, argv);
    status = diffpd::problems::Run(args, rank);
  } catch (const CLI::ParseError& e) {
    status = rank == 0 ? app.exit(e) : (e.get_exit_code() == 0 ? 0 : 2);
    if (status != 0) status = 2;
  } catch (const std::exception& e) {
    if (rank == 0) std::fprintf(stderr, "diffpd-mpi: error: %s\n", e.what());
    status = 2;
  }
  MPI_Finalize();
  return status;
}
