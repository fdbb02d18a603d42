#include "calibration/calibrate_starfish.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

#include "cli/commands.h"
#include "diffpd/csv_fields.h"
#include "diffpd/error.h"
#include "diffpd/input_file.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/core/least_squares_loss.h"
#include "diffpd/solvers/core/marker_residuals.h"
#include "diffpd/solvers/core/material_block.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/tetgen_io.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

constexpr double kMm = 1e-3;
constexpr const char* kTetgenSwitches = "pq2Y";
constexpr double kDensity = 400;             // kg/m^3
constexpr double kMuscleStiffness = 2e6;     // Pa
constexpr double kCentralHalfWidth = 0.018;  // m: the fixed central column, |y|, |z| < 18 mm
constexpr double kStripHalfWidth = 0.0075;   // m: an arm's central strip
constexpr double kFaceDistance = 0.001;      // m: flat-face layer / markers
// A muscle element has a face (>= 3 nodes) on the flat face: its fibre
// stretch along the arm is then the flat face's own stretch, so contraction
// shortens the face and curls the arm. (Elements with only 1-2 nodes there
// span the arm's thickness near the tips and shorten it without bending.)
constexpr int kMuscleFaceNodes = 3;
constexpr double kMarkerBand = 0.004;  // m: |z - target| of a marker candidate
constexpr std::array<double, 4> kMarkerTargetZ = {-0.070, -0.040, 0.0362, 0.0632};
constexpr double kLossScale = 0.002;  // m: residuals in units of 2 mm
// Fit bounds and defaults.
constexpr double kMinE = 1e4, kMaxE = 5e6, kMinNu = 0.2, kMaxNu = 0.45;
constexpr double kMaxSlack = 0.015;                     // m: slack in [0, 15 mm]
constexpr double kMinLag = 1e-3, kMaxLag = 0.5;         // s: log lag in [log 1 ms, log 0.5 s]
constexpr double kMinLength = 0.03, kMaxLength = 0.13;  // m: log tendon length in [log 30 mm, log 130 mm]
constexpr double kSlackSmoothing = 0.001;               // m: width of the slack's quadratic onset
constexpr double kFitStart = 1.0;                       // s: the tendon first moves at 1.18 s in cyclic1
constexpr double kFitSeconds = 2.0;                     // s
constexpr double kDefaultSeconds = 10;
constexpr int kDefaultIterations = 10;

const char* const kColumns[10] = {"time", "tendon", "M1 x", "M1 y", "M2 x", "M2 y", "M3 x", "M3 y", "M4 x", "M4 y"};

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

double Sigmoid(double u) { return 1 / (1 + std::exp(-u)); }
double Logit(double s) { return std::log(s / (1 - s)); }

// The fit's objective over the bounded coordinates u (5 numbers: see
// StarfishCalibration::FromCoordinates and ActuationFromCoordinates): the
// model's scalar loss (its only row) with its reverse-mode gradient, chained
// through the coordinate maps.
// With arms (StarfishRegions::kBodyArms) u has a sixth coordinate, the arms'
// E, and the model's material block is {E, nu, E_arms, nu_arms} with nu_arms
// tied to nu.
class BoundedLoss : public ceres::FirstOrderFunction {
 public:
  BoundedLoss(solvers::RolloutFunction* model, double density, bool arms)
      : model_(model), density_(density), arms_(arms) {}
  bool Evaluate(const double* u, double* cost, double* gradient) const override {
    const MaterialParameters m = StarfishCalibration::FromCoordinates(u, density_);
    const StarfishActuation a = StarfishCalibration::ActuationFromCoordinates(u + 2);
    const double arms_e = arms_ ? StarfishCalibration::FromCoordinates(u + 5, density_).youngs_modulus : 0;
    VectorXd p(arms_ ? 7 : 5);
    if (arms_)
      p << m.youngs_modulus, m.poissons_ratio, arms_e, m.poissons_ratio, a.slack, a.lag, a.length;
    else
      p << m.youngs_modulus, m.poissons_ratio, a.slack, a.lag, a.length;
    VectorXd g;
    if (gradient) {
      if (!model_->Gradient(p, VectorXd::Ones(1), &g, cost)) return false;
    } else {
      VectorXd value;
      if (!model_->Evaluate(p, {0}, &value, nullptr)) return false;
      *cost = value(0);
    }
    if (gradient) {
      // g: the material block (2 or 4 values) then the actuation block.
      const double* ga = g.data() + (arms_ ? 4 : 2);
      const double g_nu = arms_ ? g(1) + g(3) : g(1);
      const double se = Sigmoid(u[0]), sn = Sigmoid(u[1]), ss = Sigmoid(u[2]), sl = Sigmoid(u[3]);
      gradient[0] = g(0) * m.youngs_modulus * std::log(kMaxE / kMinE) * se * (1 - se);
      gradient[1] = g_nu * m.poissons_ratio * std::log(kMaxNu / kMinNu) * sn * (1 - sn);
      gradient[2] = ga[0] * kMaxSlack * ss * (1 - ss);
      gradient[3] = ga[1] * a.lag * std::log(kMaxLag / kMinLag) * sl * (1 - sl);
      const double st = Sigmoid(u[4]);
      gradient[4] = ga[2] * a.length * std::log(kMaxLength / kMinLength) * st * (1 - st);
      if (arms_) {
        const double sa = Sigmoid(u[5]);
        gradient[5] = g(2) * arms_e * std::log(kMaxE / kMinE) * sa * (1 - sa);
      }
    }
    return std::isfinite(*cost);
  }
  int NumParameters() const override { return arms_ ? 6 : 5; }

 private:
  solvers::RolloutFunction* model_;
  double density_;
  bool arms_;
};

// The tendon actuation model (StarfishActivations) as a parameter block
// {slack, lag, length} (m, s, m): it writes the activation of every muscle at
// every step.
class TendonActuationBlock : public solvers::ParameterBlock {
 public:
  TendonActuationBlock(std::vector<double> contraction, double h, int muscles, const StarfishActuation& start)
      : ParameterBlock(3), contraction_(std::move(contraction)), h_(h), muscles_(muscles) {
    SetInitial(Eigen::Vector3d(start.slack, start.lag, start.length));
  }
  std::string name() const override { return "tendon_actuation"; }
  void CheckFits(const Scene& scene, int num_steps) const override {
    DIFFPD_CHECK(
        static_cast<int>(scene.muscles.size()) == muscles_ && static_cast<int>(contraction_.size()) == num_steps,
        "tendon actuation for " << muscles_ << " muscles over " << contraction_.size() << " steps");
  }
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override {
    const std::vector<double> a = StarfishActivations(contraction_, h_, At(values), nullptr);
    for (size_t k = 0; k < a.size(); ++k) setup->inputs[k].activation = VectorXd::Constant(muscles_, a[k]);
  }
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override {
    std::vector<std::array<double, 3>> d;
    StarfishActivations(contraction_, h_, At(values), &d);
    out.setZero();
    for (int j = 0; j < 3; ++j)
      for (size_t k = 0; k < d.size() && k < grad.activation.size(); ++k)
        if (grad.activation[k].size()) out(j) += grad.activation[k].dot(VectorXd::Constant(muscles_, d[k][j]));
  }
  int FirstAffectedState(int j) const override { return 1; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const solvers::RolloutSetup& setup,
                   InputDirection* direction) const override {
    std::vector<std::array<double, 3>> d;
    StarfishActivations(contraction_, h_, At(values), &d);
    for (size_t k = 0; k < d.size(); ++k) direction->activation[k] = VectorXd::Constant(muscles_, d[k][j]);
  }

 private:
  static StarfishActuation At(const Eigen::Ref<const VectorXd>& values) {
    return StarfishActuation{values(0), values(1), values(2)};
  }
  std::vector<double> contraction_;
  double h_;
  int muscles_;
};

class FitTable : public ceres::IterationCallback {
 public:
  FitTable(FILE* log, const double* u, double density, bool arms) : log_(log), u_(u), density_(density), arms_(arms) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0) {
      std::fprintf(log_, "%4s %13s %11s %11s %9s %14s %14s %9s %9s %9s", "iter", "loss", "loss_change", "|gradient|",
                   "total_t", "youngs_modulus", "poissons_ratio", "slack_mm", "lag_s", "length_mm");
      std::fprintf(log_, arms_ ? " %14s\n" : "\n", "arms_youngs_modulus");
    }
    const MaterialParameters m = StarfishCalibration::FromCoordinates(u_, density_);
    const StarfishActuation a = StarfishCalibration::ActuationFromCoordinates(u_ + 2);
    std::fprintf(log_, "%4d %13.6e %11.3e %11.3e %9.2f %14.6g %14.6g %9.4f %9.4f %9.3f", s.iteration, s.cost,
                 s.cost_change, s.gradient_max_norm, s.cumulative_time_in_seconds, m.youngs_modulus, m.poissons_ratio,
                 a.slack / kMm, a.lag, a.length / kMm);
    if (arms_) std::fprintf(log_, " %14.6g", StarfishCalibration::FromCoordinates(u_ + 5, density_).youngs_modulus);
    std::fprintf(log_, "\n");
    std::fflush(log_);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  FILE* log_;
  const double* u_;
  double density_;
  bool arms_;
};

// Per camera frame: time (s), tendon (mm), activation, and per marker the
// simulated and captured x and z displacements (mm), to
// <dir>/<recording stem>_trace.csv.
void WriteTrace(const std::string& dir, const Mesh& mesh, const Rollout& rollout, const StarfishRecording& rec,
                const StarfishWindow& w, int substeps) {
  std::filesystem::create_directories(dir);
  const std::string path =
      (std::filesystem::path(dir) / (std::filesystem::path(rec.path).stem().string() + "_trace.csv")).string();
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
  const std::array<int, 4> vertices = StarfishCalibration::MarkerVertices(mesh);
  out << "time_s,tendon_mm,activation";
  for (int m = 1; m <= 4; ++m) out << ",M" << m << "_sim_x,M" << m << "_cap_x,M" << m << "_sim_z,M" << m << "_cap_z";
  out << "\n";
  const State& s0 = rollout.states[0];
  for (int j = w.first; j <= w.last; ++j) {
    const int k = (j - w.first) * substeps;
    const State& s = rollout.states[k];
    const int input = std::min(k, static_cast<int>(rollout.inputs.size()) - 1);
    out << rec.time[j] << "," << rec.tendon[j] / kMm << "," << rollout.inputs[input].activation(0);
    for (int m = 0; m < 4; ++m) {
      const int v = vertices[m];
      out << "," << (s.x(3 * v) - s0.x(3 * v)) / kMm << ","
          << (rec.markers[j][2 * m] - rec.markers[w.first][2 * m]) / kMm << ","
          << (s.x(3 * v + 2) - s0.x(3 * v + 2)) / kMm << ","
          << -(rec.markers[j][2 * m + 1] - rec.markers[w.first][2 * m + 1]) / kMm;
    }
    out << "\n";
  }
}

double WindowTimeStep(const StarfishRecording& rec, const StarfishWindow& w, int substeps) {
  return (rec.time[w.last] - rec.time[w.first]) / (w.num_frames() - 1) / substeps;
}

}  // namespace

namespace {

// StarfishActivations' recurrence after its checks of h and the actuation;
// *first_negative is the first step with a < 0 (-1: none), where it stops.
std::vector<double> Activations(const std::vector<double>& c, double h, const StarfishActuation& act,
                                std::vector<std::array<double, 3>>* derivatives, int* first_negative) {
  if (!(std::isfinite(h) && h > 0)) throw InvalidInputError("time step = " + Num(h) + " is invalid: must be > 0 (s)");
  if (!(std::isfinite(act.slack) && act.slack >= 0))
    throw InvalidInputError("tendon slack = " + Num(act.slack) + " is invalid: must be finite and >= 0 (m)");
  if (!(std::isfinite(act.lag) && act.lag >= 0))
    throw InvalidInputError("tendon lag = " + Num(act.lag) + " is invalid: must be finite and >= 0 (s)");
  if (!(std::isfinite(act.length) && act.length > 0))
    throw InvalidInputError("tendon length = " + Num(act.length) + " is invalid: must be finite and > 0 (m)");
  const size_t n = c.size();
  std::vector<double> a(n);
  if (derivatives) derivatives->assign(n, {0, 0, 0});
  double f = n ? c[0] : 0, df = 0;  // filtered contraction and its derivative in lag
  const double w = kSlackSmoothing, L = act.length;
  for (size_t k = 0; k < n; ++k) {
    const double f_new = (act.lag * f + h * c[k]) / (act.lag + h);
    df = (f - f_new + act.lag * df) / (act.lag + h);
    f = f_new;
    const double x = f - act.slack;
    const double hinge = x <= 0 ? 0 : x < w ? x * x / (2 * w) : x - w / 2;
    const double slope = x <= 0 ? 0 : x < w ? x / w : 1;
    a[k] = 1 - hinge / L;
    if (a[k] < 0) {
      *first_negative = static_cast<int>(k);
      return a;
    }
    if (derivatives) (*derivatives)[k] = {slope / L, -slope * df / L, hinge / (L * L)};
  }
  *first_negative = -1;
  return a;
}

// "activation -0.2 < 0 (filtered tendon contraction 0.079 m, slack 0 m,
// length 0.065 m)" of step k.
std::string NegativeActivation(const std::vector<double>& a, int k, const StarfishActuation& act) {
  return "activation " + Num(a[k]) + " < 0 (the filtered contraction exceeds slack + length: slack " + Num(act.slack) +
         " m, length " + Num(act.length) + " m)";
}

}  // namespace

std::vector<double> StarfishActivations(const std::vector<double>& c, double h, const StarfishActuation& act,
                                        std::vector<std::array<double, 3>>* derivatives) {
  int negative = -1;
  std::vector<double> a = Activations(c, h, act, derivatives, &negative);
  if (negative >= 0)
    throw InvalidInputError("tendon: " + NegativeActivation(a, negative, act) + " at step " + std::to_string(negative));
  return a;
}

StarfishRecording ReadStarfishRecording(const std::string& path) {
  std::ifstream in = OpenInputFile(path);
  StarfishRecording rec;
  rec.path = path;
  std::string line;
  int number = 0;
  if (!std::getline(in, line)) throw InvalidInputError(path + ": empty file (expected a header row and data rows)");
  ++number;
  {
    const std::vector<std::string> header = SplitCsvLine(line);
    if (header.size() != 10)
      throw InvalidInputError(path + ":1: expected a header row of 10 column labels, got " +
                              std::to_string(header.size()) + " fields");
    double v;
    if (ParseCsvNumber(header[0], &v))
      throw InvalidInputError(path + ":1: expected a header row of column labels, got the number '" + header[0] + "'");
  }
  while (std::getline(in, line)) {
    ++number;
    if (TrimCsvField(line).empty()) continue;
    const std::string where = path + ":" + std::to_string(number) + ": ";
    const std::vector<std::string> fields = SplitCsvLine(line);
    if (fields.size() != 10)
      throw InvalidInputError(where + "expected 10 fields (time ms, tendon mm, M1 x, M1 y, ..., M4 x, M4 y), got " +
                              std::to_string(fields.size()));
    double v[10];
    for (int c = 0; c < 10; ++c)
      if (!ParseCsvNumber(fields[c], &v[c]))
        throw InvalidInputError(where + kColumns[c] + " is not a number: '" + fields[c] + "'");
    if (!std::isfinite(v[0]))
      throw InvalidInputError(where + "time = " + Num(v[0]) + " is invalid: must be finite (ms)");
    if (std::isinf(v[1]))
      throw InvalidInputError(where + "tendon = " + Num(v[1]) + " is invalid: must be finite or NaN (mm)");
    for (int c = 2; c < 10; ++c)
      if (!(std::isfinite(v[c]) && std::abs(v[c] * kMm) <= kMaxMarkerCoordinate))
        throw InvalidInputError(where + kColumns[c] + " = " + Num(v[c]) +
                                " is invalid: marker coordinates must be finite and within +-" +
                                Num(kMaxMarkerCoordinate / kMm) + " (mm)");
    if (!rec.time.empty() && v[0] * kMm <= rec.time.back())
      throw InvalidInputError(where + "time " + Num(v[0]) + " ms is not after the previous row's " +
                              Num(rec.time.back() / kMm) + " ms (line " + std::to_string(rec.lines.back()) + ")");
    rec.time.push_back(v[0] * kMm);
    rec.tendon.push_back(v[1] * kMm);
    std::array<double, 8> m;
    for (int c = 0; c < 8; ++c) m[c] = v[c + 2] * kMm;
    rec.markers.push_back(m);
    rec.lines.push_back(number);
  }
  if (rec.time.empty()) throw InvalidInputError(path + ": no data rows");
  return rec;
}

StarfishWindow MakeStarfishWindow(const StarfishRecording& rec, double start, double seconds) {
  if (!(std::isfinite(seconds) && seconds > 0))
    throw InvalidInputError("seconds = " + Num(seconds) + " is invalid: must be finite and > 0 (s)");
  if (!(std::isfinite(start) && start >= 0))
    throw InvalidInputError("window start = " + Num(start) + " is invalid: must be finite and >= 0 (s)");
  StarfishWindow w;
  const double t0 = rec.time.front() + start;
  w.first = 0;
  while (w.first < rec.num_rows() && rec.time[w.first] < t0 - 1e-9) ++w.first;
  if (w.first == rec.num_rows())
    throw InvalidInputError(rec.path + ": no row at or after " + Num(start) + " s (the recording lasts " +
                            Num(rec.time.back() - rec.time.front()) + " s)");
  if (std::isnan(rec.tendon[w.first]))
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[w.first]) +
                            ": tendon contraction is NaN at the window's first row (t = " + Num(rec.time[w.first]) +
                            " s): nothing to simulate");
  const double end = rec.time[w.first] + seconds;
  w.last = w.first;
  while (w.last + 1 < rec.num_rows() && rec.time[w.last + 1] <= end + 1e-9 && !std::isnan(rec.tendon[w.last + 1]))
    ++w.last;
  if (w.last + 1 < rec.num_rows() && rec.time[w.last + 1] <= end + 1e-9) {
    std::ostringstream note;
    note << rec.path << ":" << rec.lines[w.last + 1] << ": tendon contraction is NaN from t = " << rec.time[w.last + 1]
         << " s; the window stops before it (" << rec.time[w.last] - rec.time[w.first] << " s instead of " << seconds
         << " s)";
    w.note = note.str();
  } else if (w.last + 1 == rec.num_rows() && rec.time[w.last] < end - 0.5 / StarfishCalibration::kFrameRate) {
    std::ostringstream note;
    note << rec.path << ": the recording ends " << rec.time[w.last] - rec.time[w.first]
         << " s after the window's start (asked for " << seconds << " s)";
    w.note = note.str();
  }
  if (w.last == w.first)
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[w.first]) +
                            ": the window has a single usable row; need at least two");
  return w;
}

const char* ToString(StarfishRegions regions) {
  switch (regions) {
    case StarfishRegions::kNone:
      return "none";
    case StarfishRegions::kBodyArms:
      return "body-arms";
  }
  return "unknown";
}

StarfishRegions ParseStarfishRegions(const std::string& name) {
  if (name == "body-arms") return StarfishRegions::kBodyArms;
  if (name == "none") return StarfishRegions::kNone;
  throw InvalidInputError("--regions = '" + name + "' is invalid: calibrate-starfish knows 'body-arms'");
}

std::string StarfishCalibration::description() const {
  return "fit E, nu, tendon slack, servo lag and tendon length of a soft starfish swimming underwater to real captured "
         "motion, predict other recordings";
}

void StarfishCalibration::set_substeps(int substeps) {
  if (substeps < 1 || substeps > 100)
    throw InvalidInputError("substeps = " + std::to_string(substeps) + " is invalid: must be in [1, 100]");
  substeps_ = substeps;
}

Mesh StarfishCalibration::StarfishMesh() {
  const SurfaceMesh surface = ReadObj(SharedDataPath("starfish/starfish_half_simplified.obj"));
  return TetrahedralizeSurface(surface, kTetgenSwitches);
}

std::array<int, 4> StarfishCalibration::MarkerVertices(const Mesh& mesh) {
  std::array<int, 4> vertices;
  for (int m = 0; m < 4; ++m) {
    int best = -1;
    for (int i = 0; i < mesh.num_vertices(); ++i) {
      const Vec3 p = mesh.vertices.col(i);
      if (std::abs(p(0)) > kFaceDistance || std::abs(p(2) - kMarkerTargetZ[m]) > kMarkerBand) continue;
      if (best < 0 || p(1) < mesh.vertices(1, best)) best = i;
    }
    if (best < 0)
      throw InvalidInputError("starfish mesh: no vertex on the flat face within 4 mm of z = " + Num(kMarkerTargetZ[m]) +
                              " m for marker M" + std::to_string(m + 1));
    vertices[m] = best;
  }
  return vertices;
}

Scene StarfishCalibration::MakeScene() const {
  Scene scene;
  scene.mesh = StarfishMesh();
  scene.material = MaterialParameters{5e5, 0.4, kDensity};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  const Mesh& mesh = scene.mesh;
  std::vector<int> column;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (std::abs(mesh.vertices(1, i)) < kCentralHalfWidth && std::abs(mesh.vertices(2, i)) < kCentralHalfWidth)
      column.push_back(i);
  FixNodeAxes(&scene, column, {1, 2});
  // Muscles: -z arm, +z arm, -y arm, +y arm.
  scene.muscles.resize(4);
  for (int m = 0; m < 4; ++m) {
    scene.muscles[m].stiffness = kMuscleStiffness;
    scene.muscles[m].fibers = {m < 2 ? Vec3(0, 0, 1) : Vec3(0, 1, 0)};
  }
  for (int e = 0; e < mesh.num_elements(); ++e) {
    Vec3 c = Vec3::Zero();
    int on_face = 0;
    const int nodes = static_cast<int>(mesh.elements.rows());
    for (int a = 0; a < nodes; ++a) {
      const Vec3 p = mesh.vertices.col(mesh.elements(a, e));
      c += p / nodes;
      on_face += std::abs(p(0)) <= kFaceDistance;
    }
    if (on_face < kMuscleFaceNodes) continue;
    if (std::abs(c(1)) <= kStripHalfWidth && std::abs(c(2)) > kCentralHalfWidth)
      scene.muscles[c(2) < 0 ? 0 : 1].elements.push_back(e);
    else if (std::abs(c(2)) <= kStripHalfWidth && std::abs(c(1)) > kCentralHalfWidth)
      scene.muscles[c(1) < 0 ? 2 : 3].elements.push_back(e);
  }
  if (regions_ == StarfishRegions::kBodyArms) {
    MaterialRegion arms;
    for (int e = 0; e < mesh.num_elements(); ++e) {
      Vec3 c = Vec3::Zero();
      for (int a = 0; a < mesh.elements.rows(); ++a) c += mesh.vertices.col(mesh.elements(a, e)) / mesh.elements.rows();
      if (std::abs(c(1)) > kCentralHalfWidth || std::abs(c(2)) > kCentralHalfWidth) arms.elements.push_back(e);
    }
    arms.material = scene.material;
    scene.material_regions = {arms};
  }
  Hydrodynamics water;
  water.triangles = BoundaryTriangles(mesh);
  water.fluid_density = 1e3;
  water.drag_tangential = 0.05;
  water.drag_normal = 2.05;
  water.thrust = 0;
  scene.hydrodynamics = water;
  return scene;
}

SolverOptions StarfishCalibration::Options(Method method, int threads) const {
  SolverOptions options;
  options.method = method;
  options.time_step = default_time_step();
  options.rel_tolerance = 1e-3;
  options.abs_tolerance = 1e-6;
  options.max_iterations = 5000;
  options.backward_rel_tolerance = 1e-8;
  options.num_threads = threads;
  return options;
}

std::vector<double> StarfishCalibration::WindowContractions(const StarfishRecording& rec,
                                                            const StarfishWindow& w) const {
  std::vector<double> c((w.num_frames() - 1) * substeps_);
  for (size_t i = 0; i < c.size(); ++i) c[i] = rec.tendon[w.first + static_cast<int>(i) / substeps_];
  return c;
}

std::vector<StepInput> StarfishCalibration::WindowInputs(const StarfishRecording& rec, const StarfishWindow& w,
                                                         const StarfishActuation& actuation) const {
  int negative = -1;
  const std::vector<double> a =
      Activations(WindowContractions(rec, w), WindowTimeStep(rec, w, substeps_), actuation, nullptr, &negative);
  if (negative >= 0) {
    const int row = w.first + negative / substeps_;
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[row]) + ": tendon = " +
                            Num(rec.tendon[row] / kMm) + " mm gives " + NegativeActivation(a, negative, actuation));
  }
  std::vector<StepInput> inputs(a.size());
  for (size_t i = 0; i < a.size(); ++i) inputs[i].activation = VectorXd::Constant(4, a[i]);
  return inputs;
}

State StarfishCalibration::WindowInitialState(Simulator& sim, const StarfishRecording& rec, const StarfishWindow& w,
                                              const StarfishActuation& actuation) const {
  State s = sim.RestState();
  int negative = -1;
  const std::vector<double> first = Activations({rec.tendon[w.first]}, 1, actuation, nullptr, &negative);
  if (negative >= 0)
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[w.first]) + ": tendon = " +
                            Num(rec.tendon[w.first] / kMm) + " mm gives " + NegativeActivation(first, 0, actuation));
  const double a = first[0];
  if (a == 1) return s;
  StepInput input;
  input.activation = VectorXd::Constant(4, a);
  s.x = sim.SolveQuasiStatic(s.x, input);
  return s;
}

CapturedMotion StarfishCalibration::WindowMotion(const Mesh& mesh, const State& initial, const StarfishRecording& rec,
                                                 const StarfishWindow& w) const {
  const std::array<int, 4> vertices = MarkerVertices(mesh);
  const double h = WindowTimeStep(rec, w, substeps_);
  double total_weight = 0;
  for (double wm : kMarkerWeights) total_weight += wm;
  const int frames = w.num_frames() - 1;
  CapturedMotion motion;
  for (int m = 0; m < 4; ++m) motion.markers.push_back(Marker{m, vertices[m], -1, Vec3::Zero(), 0});
  const std::array<double, 8>& ref = rec.markers[w.first];
  for (int j = w.first + 1; j <= w.last; ++j) {
    for (int m = 0; m < 4; ++m) {
      MarkerSample s;
      s.time = (j - w.first) * substeps_ * h;
      s.marker = m;
      s.position = initial.x.segment<3>(3 * vertices[m]);
      s.position(0) += rec.markers[j][2 * m] - ref[2 * m];
      s.position(2) -= rec.markers[j][2 * m + 1] - ref[2 * m + 1];
      const double weight = std::sqrt(kMarkerWeights[m] / (total_weight * frames)) / kLossScale;
      s.weight = Vec3(weight, 0, weight);
      s.line = rec.lines[j];
      motion.samples.push_back(s);
    }
  }
  motion.Validate(rec.path);  // a problem names the recording's file and row
  return motion;
}

StarfishErrors StarfishCalibration::WindowErrors(const Mesh& mesh, const std::vector<State>& states,
                                                 const StarfishRecording& rec, const StarfishWindow& w) const {
  const std::array<int, 4> vertices = MarkerVertices(mesh);
  DIFFPD_CHECK(static_cast<int>(states.size()) >= (w.num_frames() - 1) * substeps_ + 1,
               "WindowErrors: the rollout does not cover the window");
  double total_weight = 0;
  for (double wm : kMarkerWeights) total_weight += wm;
  const std::array<double, 8>& ref = rec.markers[w.first];
  double sum = 0, sum_rel = 0, sum_w = 0;
  StarfishErrors out;
  for (int j = w.first + 1; j <= w.last; ++j) {
    const State& s = states[(j - w.first) * substeps_];
    Eigen::Vector2d sim[4], cap[4];
    double mean_sim = 0, mean_cap = 0;
    for (int m = 0; m < 4; ++m) {
      const int v = vertices[m];
      sim[m] = Eigen::Vector2d(s.x(3 * v) - states[0].x(3 * v), s.x(3 * v + 2) - states[0].x(3 * v + 2));
      cap[m] = Eigen::Vector2d(rec.markers[j][2 * m] - ref[2 * m], -(rec.markers[j][2 * m + 1] - ref[2 * m + 1]));
      mean_sim += sim[m](0) / 4;
      mean_cap += cap[m](0) / 4;
    }
    for (int m = 0; m < 4; ++m) {
      const Eigen::Vector2d e = sim[m] - cap[m];
      sum += e.squaredNorm();
      sum_w += kMarkerWeights[m] * e.squaredNorm() / total_weight;
      sum_rel += (e - Eigen::Vector2d(mean_sim - mean_cap, 0)).squaredNorm();
    }
    ++out.frames;
  }
  if (out.frames > 0) {
    out.rmse = std::sqrt(sum / (4.0 * out.frames));
    out.arm_relative_rmse = std::sqrt(sum_rel / (4.0 * out.frames));
    out.weighted_rms = std::sqrt(sum_w / out.frames);
  }
  return out;
}

std::unique_ptr<solvers::RolloutFunction> StarfishCalibration::MakeModel(const StarfishRecording& rec,
                                                                         const StarfishWindow& w,
                                                                         const SolverOptions& options,
                                                                         const MaterialParameters& material,
                                                                         const StarfishActuation& actuation) const {
  using solvers::MaterialField;
  Scene scene = MakeScene();
  scene.material = material;
  for (MaterialRegion& region : scene.material_regions) region.material = material;
  SolverOptions solver = options;
  solver.time_step = WindowTimeStep(rec, w, substeps_);
  std::vector<StepInput> inputs = WindowInputs(rec, w, actuation);
  const int steps = static_cast<int>(inputs.size());
  State initial;
  {
    Simulator sim(scene, solver);
    initial = WindowInitialState(sim, rec, w, actuation);
  }
  auto model = std::make_unique<solvers::RolloutFunction>(scene, solver, steps);
  model->SetInitialState(initial);
  model->SetInputs(std::move(inputs));
  std::vector<solvers::MaterialBlock::Entry> fitted = {MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio};
  if (regions_ == StarfishRegions::kBodyArms) {
    fitted.push_back({MaterialField::kYoungsModulus, 0});
    fitted.push_back({MaterialField::kPoissonsRatio, 0});
  }
  model->AddBlock(std::make_unique<solvers::MaterialBlock>(fitted, scene));
  model->AddBlock(std::make_unique<TendonActuationBlock>(WindowContractions(rec, w), solver.time_step,
                                                         static_cast<int>(scene.muscles.size()), actuation));
  model->AddFunctional(std::make_unique<solvers::LeastSquaresLoss>(std::make_unique<solvers::MarkerResiduals>(
      WindowMotion(scene.mesh, initial, rec, w), scene.mesh, solver.time_step, steps)));
  return model;
}

StarfishFit StarfishCalibration::Fit(const StarfishRecording& rec, const StarfishWindow& w,
                                     const SolverOptions& options, const MaterialParameters& guess,
                                     const StarfishActuation& actuation_guess, int max_iterations, FILE* log) const {
  std::unique_ptr<solvers::RolloutFunction> model = MakeModel(rec, w, options, guess, actuation_guess);
  const bool arms = regions_ == StarfishRegions::kBodyArms;
  double u[6];
  ToCoordinates(guess, u);
  ActuationToCoordinates(actuation_guess, u + 2);
  if (arms) {
    double arms_u[2];
    ToCoordinates(guess, arms_u);
    u[5] = arms_u[0];
  }
  ceres::GradientProblem problem(new BoundedLoss(model.get(), guess.density, arms));
  ceres::GradientProblemSolver::Options solver_options;
  solver_options.line_search_direction_type = ceres::LBFGS;
  // Scale L-BFGS' initial inverse Hessian by the observed curvature: the
  // first step is the gradient's length, the later ones Newton-like.
  solver_options.use_approximate_eigenvalue_bfgs_scaling = true;
  solver_options.max_num_iterations = max_iterations;
  solver_options.function_tolerance = 1e-5;
  solver_options.gradient_tolerance = 1e-8;
  solver_options.parameter_tolerance = 1e-5;
  solver_options.logging_type = ceres::SILENT;
  solver_options.update_state_every_iteration = true;
  FitTable table(log, u, guess.density, arms);
  if (log) solver_options.callbacks.push_back(&table);
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(solver_options, problem, u, &summary);
  StarfishFit fit;
  fit.material = FromCoordinates(u, guess.density);
  fit.actuation = ActuationFromCoordinates(u + 2);
  if (arms) {
    MaterialParameters arms_material = fit.material;
    arms_material.youngs_modulus = FromCoordinates(u + 5, guess.density).youngs_modulus;
    fit.region_materials = {arms_material};
  }
  fit.initial_cost = summary.initial_cost;
  fit.final_cost = summary.final_cost;
  fit.iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit.usable = summary.IsSolutionUsable();
  fit.termination = summary.message;
  fit.statistics = model->statistics();
  return fit;
}

MaterialParameters StarfishCalibration::FromCoordinates(const double* u, double density) {
  MaterialParameters m;
  m.youngs_modulus = std::exp(std::log(kMinE) + std::log(kMaxE / kMinE) * Sigmoid(u[0]));
  m.poissons_ratio = std::exp(std::log(kMinNu) + std::log(kMaxNu / kMinNu) * Sigmoid(u[1]));
  m.density = density;
  return m;
}

void StarfishCalibration::ToCoordinates(const MaterialParameters& m, double* u) {
  if (!(m.youngs_modulus > kMinE && m.youngs_modulus < kMaxE))
    throw InvalidInputError("youngs_modulus = " + Num(m.youngs_modulus) +
                            " is outside the fit's interval (1e4, 5e6) Pa");
  if (!(m.poissons_ratio > kMinNu && m.poissons_ratio < kMaxNu))
    throw InvalidInputError("poissons_ratio = " + Num(m.poissons_ratio) + " is outside the fit's interval (0.2, 0.45)");
  u[0] = Logit(std::log(m.youngs_modulus / kMinE) / std::log(kMaxE / kMinE));
  u[1] = Logit(std::log(m.poissons_ratio / kMinNu) / std::log(kMaxNu / kMinNu));
}

StarfishActuation StarfishCalibration::ActuationFromCoordinates(const double* u) {
  StarfishActuation a;
  a.slack = kMaxSlack * Sigmoid(u[0]);
  a.lag = std::exp(std::log(kMinLag) + std::log(kMaxLag / kMinLag) * Sigmoid(u[1]));
  a.length = std::exp(std::log(kMinLength) + std::log(kMaxLength / kMinLength) * Sigmoid(u[2]));
  return a;
}

void StarfishCalibration::ActuationToCoordinates(const StarfishActuation& a, double* u) {
  if (!(a.slack > 0 && a.slack < kMaxSlack))
    throw InvalidInputError("tendon slack = " + Num(a.slack) + " is outside the fit's interval (0, 0.015) m");
  if (!(a.lag > kMinLag && a.lag < kMaxLag))
    throw InvalidInputError("tendon lag = " + Num(a.lag) + " is outside the fit's interval (0.001, 0.5) s");
  u[0] = Logit(a.slack / kMaxSlack);
  if (!(a.length > kMinLength && a.length < kMaxLength))
    throw InvalidInputError("tendon length = " + Num(a.length) + " is outside the fit's interval (0.03, 0.13) m");
  u[1] = Logit(std::log(a.lag / kMinLag) / std::log(kMaxLag / kMinLag));
  u[2] = Logit(std::log(a.length / kMinLength) / std::log(kMaxLength / kMinLength));
}

int StarfishCalibration::Run(const CommandArgs& args) const {
  RefuseSimulatorTuning(args, name());
  if (!args.regions.empty()) {  // a copy with the regions, run without the option
    StarfishCalibration with_regions = *this;
    with_regions.set_regions(ParseStarfishRegions(args.regions));
    CommandArgs rest = args;
    rest.regions.clear();
    return with_regions.Run(rest);
  }
  if (args.steps > 0 || args.dt > 0)
    throw InvalidInputError("--steps and --dt are fixed by the recordings of " + name() + " (60 Hz camera frames, " +
                            std::to_string(substeps_) + " steps per frame)");
  if (!args.data_file.empty())
    throw InvalidInputError(name() + " reads its recordings from --calibrate and --predict, not --data");
  const auto start_clock = std::chrono::steady_clock::now();
  FILE* log = args.json ? stderr : stdout;
  const double seconds = args.seconds > 0 ? args.seconds : kDefaultSeconds;
  if (args.seconds != -1 && !(args.seconds > 0))
    throw InvalidInputError("--seconds = " + Num(args.seconds) + " is invalid: must be > 0 (s)");
  std::string calibrate_path = args.calibrate_file;
  std::vector<std::string> predict_paths = args.predict_files;
  if (calibrate_path.empty()) {
    calibrate_path = SharedDataPath("starfish/data_horizontal_cyclic1.csv");
    if (predict_paths.empty()) predict_paths = {calibrate_path, SharedDataPath("starfish/data_horizontal_cyclic2.csv")};
  } else if (predict_paths.empty()) {
    predict_paths = {calibrate_path};
  }
  // pd-lbfgs unless chosen: --methods (first entry) or a --method other than
  // the command line's default (pd).
  const Method method = !args.methods.empty()        ? ParseMethod(args.methods.front())
                        : args.method != Method::kPd ? args.method
                                                     : Method::kPdLbfgs;
  const SolverOptions options = Options(method, args.threads);

  // Read everything first: bad input fails before any simulation.
  const StarfishRecording calibration = ReadStarfishRecording(calibrate_path);
  std::vector<StarfishRecording> predictions;
  for (const std::string& p : predict_paths) predictions.push_back(ReadStarfishRecording(p));
  const StarfishWindow fit_window = MakeStarfishWindow(calibration, kFitStart, kFitSeconds);
  std::vector<StarfishWindow> windows;
  for (const StarfishRecording& r : predictions) windows.push_back(MakeStarfishWindow(r, 0, seconds));

  const Scene scene = MakeScene();
  std::fprintf(log, "# %s: %s\n", name().c_str(), description().c_str());
  std::fprintf(log,
               "# mesh: TetGen -%s of starfish_half_simplified.obj: %d nodes, %d tets, %d DoFs (%zu with y, z fixed)\n",
               kTetgenSwitches, scene.mesh.num_vertices(), scene.mesh.num_elements(), scene.mesh.num_dofs(),
               scene.dirichlet.dofs.size() / 2);
  std::fprintf(log,
               "# muscles (elements): -z %zu, +z %zu, -y %zu, +y %zu; %d wetted triangles; %s, %d steps per frame\n",
               scene.muscles[0].elements.size(), scene.muscles[1].elements.size(), scene.muscles[2].elements.size(),
               scene.muscles[3].elements.size(), static_cast<int>(scene.hydrodynamics->triangles.cols()),
               ToString(method), substeps_);
  std::fprintf(log, "# calibration: %s, rows %d..%d (t = %.3f..%.3f s, %d frames), marker weights 10/1/1/10\n",
               calibrate_path.c_str(), calibration.lines[fit_window.first], calibration.lines[fit_window.last],
               calibration.time[fit_window.first], calibration.time[fit_window.last], fit_window.num_frames());
  if (!fit_window.note.empty()) std::fprintf(log, "# note: %s\n", fit_window.note.c_str());

  // The fit.
  const MaterialParameters guess = scene.material;
  const StarfishActuation actuation_guess = ActuationGuess();
  std::fprintf(
      log,
      "# fit: Ceres L-BFGS on (log E, log nu, slack, log lag, log length%s) mapped into E in [1e4, 5e6] "
      "Pa, nu in [0.2, 0.45], tendon slack in [0, 15] mm, servo lag in [1, 500] ms, tendon length in [30, 130] mm; "
      "loss = 1/2 weighted mean squared marker error / (2 mm)^2\n",
      regions_ == StarfishRegions::kBodyArms ? ", log E_arms" : "");
  if (regions_ == StarfishRegions::kBodyArms)
    std::fprintf(log,
                 "# regions: body-arms: E of the %zu arm elements (centroid beyond |y|, |z| < 18 mm) fitted apart "
                 "from the body's %zu; nu and density shared\n",
                 scene.material_regions[0].elements.size(),
                 scene.mesh.num_elements() - scene.material_regions[0].elements.size());
  const StarfishFit fit = Fit(calibration, fit_window, options, guess, actuation_guess,
                              args.max_iterations >= 0 ? args.max_iterations : kDefaultIterations, log);
  const MaterialParameters& fitted = fit.material;
  const StarfishActuation& actuation = fit.actuation;
  const solvers::RolloutStatistics& stats = fit.statistics;
  std::fprintf(log,
               "# fit: %s after %d iterations; E = %.6g Pa, nu = %.6g, slack = %.3f mm, lag = %.4f s, "
               "length = %.2f mm; loss %.6e -> %.6e\n",
               fit.termination.c_str(), fit.iterations, fitted.youngs_modulus, fitted.poissons_ratio,
               actuation.slack / kMm, actuation.lag, actuation.length / kMm, fit.initial_cost, fit.final_cost);
  std::fprintf(log, "# fit: %ld rollouts (%.2f s forward), %ld gradients (%.2f s backward), %ld failed\n",
               stats.rollouts, stats.forward_seconds, stats.gradients, stats.backward_seconds, stats.failures);
  if (!fit.region_materials.empty())
    std::fprintf(log, "# fit: arms E = %.6g Pa (body E = %.6g Pa, ratio %.3g)\n",
                 fit.region_materials[0].youngs_modulus, fitted.youngs_modulus,
                 fit.region_materials[0].youngs_modulus / fitted.youngs_modulus);
  if (stats.failures > 0) std::fprintf(log, "# last failure: %s\n", stats.last_error.c_str());

  // Predictions.
  nlohmann::json files = nlohmann::json::array();
  std::fprintf(log,
               "\n# predictions with the fitted material (first %g s of each file)\n%-40s %8s %8s %10s %12s %10s\n",
               seconds, "file", "seconds", "frames", "rmse_mm", "arm_rel_mm", "sim_s");
  for (size_t f = 0; f < predictions.size(); ++f) {
    const StarfishRecording& rec = predictions[f];
    const StarfishWindow& w = windows[f];
    if (!w.note.empty()) std::fprintf(log, "# note: %s\n", w.note.c_str());
    Scene s = scene;
    s.material = fitted;
    for (size_t r = 0; r < fit.region_materials.size(); ++r) s.material_regions[r].material = fit.region_materials[r];
    SolverOptions o = options;
    o.time_step = WindowTimeStep(rec, w, substeps_);
    Simulator sim(s, o);
    const auto t0 = std::chrono::steady_clock::now();
    const State initial = WindowInitialState(sim, rec, w, actuation);
    const Rollout rollout = sim.Simulate(initial, WindowInputs(rec, w, actuation));
    const double sim_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const StarfishErrors e = WindowErrors(s.mesh, rollout.states, rec, w);
    if (!args.out_dir.empty()) WriteTrace(args.out_dir, s.mesh, rollout, rec, w, substeps_);
    const double window_seconds = rec.time[w.last] - rec.time[w.first];
    std::fprintf(log, "%-40s %8.3f %8d %10.3f %12.3f %10.1f\n", rec.path.c_str(), window_seconds, w.num_frames(),
                 e.rmse / kMm, e.arm_relative_rmse / kMm, sim_seconds);
    std::fflush(log);
    nlohmann::json j = {{"file", rec.path},
                        {"rmse_mm", e.rmse / kMm},
                        {"arm_relative_rmse_mm", e.arm_relative_rmse / kMm},
                        {"weighted_rms_mm", e.weighted_rms / kMm},
                        {"seconds", window_seconds},
                        {"frames", w.num_frames()},
                        {"used_for_calibration", rec.path == calibrate_path},
                        {"simulate_seconds", sim_seconds}};
    if (!w.note.empty()) j["note"] = w.note;
    files.push_back(j);
  }

  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_clock).count();
  std::fprintf(log, "# total %.1f s\n", total);
  if (args.json) {
    nlohmann::json out = {{"problem", name()},
                          {"youngs_modulus", fitted.youngs_modulus},
                          {"poissons_ratio", fitted.poissons_ratio},
                          {"density", fitted.density},
                          {"tendon_slack_mm", actuation.slack / kMm},
                          {"tendon_lag_s", actuation.lag},
                          {"tendon_length_mm", actuation.length / kMm},
                          {"truth", nlohmann::json::object()},
                          {"initial_guess",
                           {{"youngs_modulus", guess.youngs_modulus},
                            {"poissons_ratio", guess.poissons_ratio},
                            {"tendon_slack_mm", actuation_guess.slack / kMm},
                            {"tendon_lag_s", actuation_guess.lag},
                            {"tendon_length_mm", actuation_guess.length / kMm}}},
                          {"method", ToString(method)},
                          {"initial_cost", fit.initial_cost},
                          {"final_cost", fit.final_cost},
                          {"iterations", fit.iterations},
                          {"evaluations", stats.rollouts},
                          {"gradient_evaluations", stats.gradients},
                          {"failed_evaluations", stats.failures},
                          {"forward_seconds", stats.forward_seconds},
                          {"backward_seconds", stats.backward_seconds},
                          {"termination", fit.termination},
                          {"usable", fit.usable},
                          {"mesh",
                           {{"nodes", scene.mesh.num_vertices()},
                            {"tets", scene.mesh.num_elements()},
                            {"tetgen_switches", kTetgenSwitches}}},
                          {"steps_per_frame", substeps_},
                          {"calibration",
                           {{"file", calibrate_path},
                            {"start_s", calibration.time[fit_window.first]},
                            {"seconds", calibration.time[fit_window.last] - calibration.time[fit_window.first]},
                            {"frames", fit_window.num_frames()},
                            {"marker_weights", kMarkerWeights}}},
                          {"files", files},
                          {"total_seconds", total}};
    out["regions"] = ToString(regions_);
    if (!fit.region_materials.empty()) out["arms_youngs_modulus"] = fit.region_materials[0].youngs_modulus;
    std::printf("%s\n", out.dump(2).c_str());
  }
  return fit.usable ? 0 : 5;
}

}  // namespace diffpd::problems
