// The driver of the trajectory-optimisation problems
// (problems/control/trajectory_optimization.h) on a tiny problem defined here: the
// PD run repeated with Newton-Cholesky and the ratio of their simulation
// times, the files `diffpd run` writes (VTK frames, objective histories,
// their PNG plot, summary.json), the JSON object's keys, the program's
// message and exit code for an infeasible problem, and option parsing.
#include "control/trajectory_optimization.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/commands.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "test_scenes.h"
#include "util/temporary_directory.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

namespace fs = std::filesystem;

struct CapturedRun {
  int code;
  std::string out, err;
};

// problem.Run(args) with stdout and stderr captured.
CapturedRun RunCaptured(const TrajectoryOptimizationProblem& problem, const CommandArgs& args) {
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const int code = problem.Run(args);
  std::string out = ::testing::internal::GetCapturedStdout();
  std::string err = ::testing::internal::GetCapturedStderr();
  return {code, std::move(out), std::move(err)};
}
using solvers::IpoptOptions;

// A free soft cube (2 x 2 x 2 hexahedra, 0.1 m) thrown by its initial
// velocity (|v| <= 1 m/s per axis): its centre of mass must travel 2 cm in x
// within K steps (objective, m^2 * 1e4) and rise by `rise` m at K
// (constraint). rise = 0.01 is easily met; 0.5 m cannot be.
class CubeThrow : public TrajectoryOptimizationProblem {
 public:
  explicit CubeThrow(double rise) : rise_(rise) {}
  std::string name() const override { return "cube-throw"; }
  std::string description() const override { return "test problem"; }
  Scene MakeScene(InstanceSize size) const override {
    Scene scene;
    scene.mesh = diffpd::testing::BoxHexMesh(2, 2, 2, 0.1, 0.1, 0.1);
    scene.material.youngs_modulus = 1e5;
    scene.material.poissons_ratio = 0.4;
    scene.material.density = 1e3;
    scene.gravity = Vec3(0, 0, -9.81);
    return scene;
  }
  int steps(InstanceSize size) const override { return 5; }
  double time_step(InstanceSize size) const override { return 0.01; }
  Ipopt::SmartPtr<solvers::RolloutNlp> MakeNlp(const SolverOptions& options, InstanceSize size) const override {
    using namespace solvers;
    Ipopt::SmartPtr<RolloutNlp> nlp =
        new RolloutNlp(std::make_unique<RolloutFunction>(MakeScene(size), options, steps(size)));
    const int n = nlp->function().scene().mesh.num_vertices();
    std::vector<int> all(n);
    for (int i = 0; i < n; ++i) all[i] = i;
    auto v0 = std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, all);
    v0->SetBounds(-1.0, 1.0);
    v0->SetInitial(Vec3(0.0, 0.0, 0.2));
    nlp->AddVariables(std::move(v0));
    const TrackedPoint com = CentreOfMass(nlp->function().simulator().LumpedMass());
    const Vec3 c0 = com.At(nlp->function().base().initial.x);
    nlp->AddObjective(
        std::make_unique<PointDistanceSquared>(com, kFinalState, c0 + Vec3(0.02, 0, 0), "travel", Vec3(1, 1, 0)), 1e4);
    nlp->AddConstraint(std::make_unique<PointCoordinate>(com, kFinalState, Vec3::UnitZ(), "rise"), c0.z() + rise_,
                       1e20);
    return nlp;
  }

 private:
  double rise_;
};

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(IpoptTrajectoryOptimizationTest, PdRunIsRepeatedWithNewtonAndTheTimeRatioIsTheirSimulationTimes) {
  const CubeThrow problem(0.01);
  OptimizationSettings settings;
  settings.size = InstanceSize::kSmall;
  settings.method = Method::kPd;
  settings.threads = 1;
  settings.log = nullptr;
  const OptimizationReport report = RunOptimization(problem, settings);
  ASSERT_EQ(report.runs.size(), 2u);
  EXPECT_EQ(report.runs[0].method, Method::kPd);
  EXPECT_EQ(report.runs[1].method, Method::kNewtonCholesky);
  for (const OptimizationRun& run : report.runs) {
    const solvers::IpoptSummary& s = run.summary;
    EXPECT_TRUE(s.succeeded()) << s.BriefReport();
    EXPECT_TRUE(run.improved) << s.BriefReport();
    EXPECT_LE(s.constraint_violation, 1e-6);
    EXPECT_GT(s.evaluations, 0);
    EXPECT_GT(s.forward_seconds, 0.0);
    EXPECT_GT(s.backward_seconds, 0.0);
  }
  // The same problem: same start, and both methods reach the same optimum.
  const auto& pd = report.runs[0].summary;
  const auto& newton = report.runs[1].summary;
  EXPECT_NEAR(pd.initial_objective, newton.initial_objective, 1e-4 * newton.initial_objective);
  EXPECT_NEAR(pd.objective, newton.objective, 1e-4 * newton.initial_objective);
  const double expected =
      (newton.forward_seconds + newton.backward_seconds) / (pd.forward_seconds + pd.backward_seconds);
  EXPECT_DOUBLE_EQ(report.newton_time_ratio, expected);

  const nlohmann::json j = ReportJson(report);
  EXPECT_EQ(j["status"], pd.status_name);
  EXPECT_EQ(j["objective"].get<double>(), pd.objective);
  EXPECT_EQ(j["initial_objective"].get<double>(), pd.initial_objective);
  EXPECT_EQ(j["constraint_violation"].get<double>(), pd.constraint_violation);
  EXPECT_EQ(j["evaluations"].get<long>(), pd.evaluations);
  EXPECT_EQ(j["forward_s"].get<double>(), pd.forward_seconds);
  EXPECT_EQ(j["backward_s"].get<double>(), pd.backward_seconds);
  EXPECT_EQ(j["method"], "pd");
  EXPECT_EQ(j["newton_cholesky"]["method"], "newton-cholesky");
  EXPECT_EQ(j["newton_cholesky"]["evaluations"].get<long>(), newton.evaluations);
  EXPECT_DOUBLE_EQ(j["newton_time_ratio"].get<double>(), expected);

  char* text = nullptr;
  size_t size = 0;
  FILE* out = open_memstream(&text, &size);
  PrintReport(report, out);
  std::fclose(out);
  const std::string table(text, size);
  std::free(text);
  char ratio_line[128];
  std::snprintf(ratio_line, sizeof(ratio_line), "newton-cholesky / pd simulation time (forward + backward): %.3f",
                expected);
  EXPECT_NE(table.find(ratio_line), std::string::npos) << table;
  EXPECT_NE(table.find("forward_s backward_s"), std::string::npos) << table;
}

TEST(IpoptTrajectoryOptimizationTest, RunWritesFramesHistoriesPlotAndOneJsonObject) {
  const testing::TemporaryDirectory temp("diffpd-ipopt-driver-files");
  const fs::path dir = temp.path();
  const CubeThrow problem(0.01);
  CommandArgs args;
  args.problem = problem.name();
  args.small = true;
  args.method = Method::kPd;
  args.threads = 1;
  args.json = true;
  args.out_dir = dir.string();
  const auto [code, out, err] = RunCaptured(problem, args);
  EXPECT_EQ(code, 0) << err;
  // stdout is exactly one JSON object with the listed keys; the log and table on stderr.
  const nlohmann::json j = nlohmann::json::parse(out);
  for (const char* key :
       {"status", "objective", "initial_objective", "constraint_violation", "evaluations", "forward_s", "backward_s"}) {
    EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j["newton_cholesky"].contains(key)) << key;
  }
  EXPECT_EQ(j["status"], "Solve_Succeeded");
  EXPECT_NE(err.find("iter    objective    inf_pr"), std::string::npos) << err;  // Ipopt's iteration log
  EXPECT_NE(err.find("newton-cholesky / pd simulation time"), std::string::npos) << err;

  // VTK frames: the .pvd lists K + 1 frames, each a .vtu file on disk.
  const fs::path pvd = dir / "frames" / "cube-throw.pvd";
  ASSERT_TRUE(fs::exists(pvd));
  int frames = 0;
  for (const auto& entry : fs::directory_iterator(dir / "frames")) frames += entry.path().extension() == ".vtu";
  EXPECT_EQ(frames, problem.steps(InstanceSize::kSmall) + 1);
  // Objective histories (one line per Ipopt iteration, from iteration 0) and the plot.
  const std::string history = ReadFile(dir / "objective_history_pd.dat");
  std::istringstream lines(history);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "# iteration objective");
  int rows = 0;
  double first = 0;
  for (int i; lines >> i;) {
    double f;
    lines >> f;
    if (rows == 0) first = f;
    EXPECT_EQ(i, rows++);
  }
  EXPECT_EQ(rows, j["iterations"].get<int>() + 1);
  EXPECT_NEAR(first, j["initial_objective"].get<double>(), 1e-12 * std::abs(first));
  EXPECT_TRUE(fs::exists(dir / "objective_history_newton-cholesky.dat"));
  const std::string png = ReadFile(dir / "objective_history.png");
  ASSERT_GT(png.size(), 8u) << "no PNG written (is gnuplot installed?)";
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(nlohmann::json::parse(ReadFile(dir / "summary.json")), j);
}

TEST(IpoptTrajectoryOptimizationTest, UnreachableConstraintIsReportedInfeasibleWithExitCode4) {
  const testing::TemporaryDirectory temp("diffpd-ipopt-driver-infeasible");
  const fs::path dir = temp.path();
  const CubeThrow problem(0.5);  // a 1 m/s throw rises under 4 cm in 50 ms
  CommandArgs args;
  args.problem = problem.name();
  args.method = Method::kNewtonCholesky;
  args.threads = 1;
  args.out_dir = dir.string();
  const auto [code, out, err] = RunCaptured(problem, args);
  EXPECT_EQ(code, 4) << out;
  EXPECT_NE(out.find("EXIT: Converged to a point of local infeasibility. Problem may be infeasible."),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("newton-cholesky: Ipopt reports the problem infeasible: the constraints cannot be met "
                     "(Infeasible_Problem_Detected); objective NOT improved"),
            std::string::npos)
      << out;
  EXPECT_NE(err.find("diffpd: cube-throw: Ipopt reports the problem infeasible: the constraints cannot be met "
                     "(Infeasible_Problem_Detected)"),
            std::string::npos)
      << err;
}

TEST(IpoptTrajectoryOptimizationTest, StepsAndTimeStepAreRefusedWithAMessage) {
  const CubeThrow problem(0.01);
  CommandArgs args;
  args.steps = 10;
  ASSERT_THROW_MESSAGE(problem.Run(args), InvalidInputError,
                       "--steps and --dt are fixed by the optimisation problem 'cube-throw'; use --small for the "
                       "reduced instance");
}

TEST(IpoptTrajectoryOptimizationTest, IpoptOptionsAreParsedByTheirValue) {
  IpoptOptions o;
  AddIpoptOption("max_iter=7", &o);
  AddIpoptOption("tol=1e-9", &o);
  AddIpoptOption("mu_strategy=adaptive", &o);
  ASSERT_EQ(o.int_options.size(), 1u);
  EXPECT_EQ(o.int_options[0], std::make_pair(std::string("max_iter"), 7));
  ASSERT_EQ(o.num_options.size(), 1u);
  EXPECT_EQ(o.num_options[0], std::make_pair(std::string("tol"), 1e-9));
  ASSERT_EQ(o.string_options.size(), 1u);
  EXPECT_EQ(o.string_options[0], std::make_pair(std::string("mu_strategy"), std::string("adaptive")));
  for (const char* bad : {"max_iter", "=3", "tol="}) {
    ASSERT_THROW_MESSAGE(AddIpoptOption(bad, &o), InvalidInputError,
                         std::string("Ipopt option '") + bad + "' is invalid: expected name=value");
  }
  EXPECT_EQ(DefaultOutputDirectory("bunny"), (fs::path("out") / "bunny").string());
}

}  // namespace
}  // namespace diffpd::problems
