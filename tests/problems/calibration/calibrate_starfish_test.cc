// calibrate-starfish (problems/calibration/calibrate_starfish.h): the real recordings are
// parsed as the fact sheet describes them, malformed files are rejected with
// messages naming file and line, the scene has the fact sheet's boundary,
// markers and muscles, the tendon-to-activation map (slack, lag) and its
// derivatives, the reverse-mode loss gradient in E, nu, slack and lag agrees
// with central finite differences, and a short fit lowers the loss; the
// least-squares model's forward-mode Jacobian, its fit and intervals; the
// metrics, baselines and trace files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "calibration/calibrate_starfish.h"
#include "calibration/starfish_plot.h"
#include "calibration/starfish_trace.h"
#include "tools/tradeoff.h"
#include "diffpd/error.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

const std::string kStarfishDir = std::string(DIFFPD_SHARED_DIR) + "/data/starfish/";
const std::string kCyclic1 = kStarfishDir + "data_horizontal_cyclic1.csv";
const std::string kCyclic2 = kStarfishDir + "data_horizontal_cyclic2.csv";
const std::string kHeader = "Time (ms),Tendon (mm),M1 X,M1 Y,M2 X,M2 Y,M3 X,M3 Y,M4 X,M4 Y\n";
const std::string kRow0 = "0,0,1,2,3,4,5,6,7,8\n";

// This program's own temporary directory (removed at exit).
const testing::TemporaryDirectory& Scratch() {
  static const testing::TemporaryDirectory directory("diffpd-starfish-recordings");
  return directory;
}

std::string WriteTemp(const std::string& name, const std::string& text) { return Scratch().WriteFile(name, text); }

std::string ReadError(const std::string& path) {
  return testing::MessageOf<InvalidInputError>([&] { ReadStarfishRecording(path); });
}

TEST(CalibrateStarfishTest, ReadsTheRealRecordingsInSiUnits) {
  const StarfishRecording r = ReadStarfishRecording(kCyclic1);
  ASSERT_EQ(r.num_rows(), 2234);
  EXPECT_EQ(r.lines.front(), 2);
  EXPECT_EQ(r.time[0], 0.0);
  EXPECT_NEAR(r.time[1], 16.666666e-3, 1e-12);
  EXPECT_EQ(r.tendon[0], 0.0);
  const double first[8] = {333.90558, 168.04053, 329.55084, 146.81335, 331.14767, 73.042511, 333.68942, 46.489552};
  for (int c = 0; c < 8; ++c) EXPECT_NEAR(r.markers[0][c], first[c] * 1e-3, 1e-12) << "column " << c + 2;
  // The tendon is NaN from line 2032 to the end (204 rows); markers never are.
  EXPECT_FALSE(std::isnan(r.tendon[2029]));
  EXPECT_TRUE(std::isnan(r.tendon[2030]));
  EXPECT_EQ(r.lines[2030], 2032);
  EXPECT_TRUE(std::isnan(r.tendon.back()));
  const StarfishRecording r2 = ReadStarfishRecording(kCyclic2);
  ASSERT_EQ(r2.num_rows(), 2493);
  EXPECT_NEAR(r2.tendon[0], 1.1938052e-3, 1e-12);  // the pre-tension
}

// A malformed recording's text and the message after "<path>".
struct BadRecording {
  std::string text;
  std::string message;
};

TEST(CalibrateStarfishTest, RejectsMalformedFilesNamingFileAndLine) {
  const std::string missing = Scratch().File("starfish_missing.csv");
  EXPECT_EQ(ReadError(missing), "cannot open '" + missing + "'");
  const std::string folder = Scratch().File("starfish_folder.csv");
  std::filesystem::create_directories(folder);
  EXPECT_EQ(ReadError(folder), "cannot open '" + folder + "': it is a directory, not a file");
  const BadRecording cases[] = {
      {"", ": empty file (expected a header row and data rows)"},
      {"a,b,c\n" + kRow0, ":1: expected a header row of 10 column labels, got 3 fields"},
      {kRow0 + kRow0, ":1: expected a header row of column labels, got the number '0'"},
      {kHeader + kRow0 + "16.7,0,1,2,3,4,5,6,7\n",
       ":3: expected 10 fields (time ms, tendon mm, M1 x, M1 y, ..., M4 x, M4 y), got 9"},
      {kHeader + kRow0 + "16.7,0,1,2,3,abc,5,6,7,8\n", ":3: M2 y is not a number: 'abc'"},
      {kHeader + kRow0 + "16.7,0,1,2,3,4,NaN,6,7,8\n",
       ":3: M3 x = nan is invalid: marker coordinates must be finite and within +-1e+09 (mm)"},
      {kHeader + kRow0 + "16.7,0,1,2,3,4,5,6,7,1e300\n",
       ":3: M4 y = 1e+300 is invalid: marker coordinates must be finite and within +-1e+09 (mm)"},
      {kHeader + kRow0 + "16.7,inf,1,2,3,4,5,6,7,8\n", ":3: tendon = inf is invalid: must be finite or NaN (mm)"},
      {kHeader + kRow0 + "16.5,0,1,2,3,4,5,6,7,8\n10,0,1,2,3,4,5,6,7,8\n",
       ":4: time 10 ms is not after the previous row's 16.5 ms (line 3)"},
      {kHeader, ": no data rows"},
  };
  for (const BadRecording& c : cases) {
    const std::string p = WriteTemp("starfish_bad.csv", c.text);
    EXPECT_EQ(ReadError(p), p + c.message) << c.text;
  }
  std::string p;
  // A NaN tendon is accepted by the reader, and the window stops before it.
  p = WriteTemp("starfish_nan_tendon.csv", kHeader + kRow0 + "16.5,1,1,2,3,4,5,6,7,8\n33,NaN,1,2,3,4,5,6,7,8\n");
  const StarfishRecording r = ReadStarfishRecording(p);
  const StarfishWindow w = MakeStarfishWindow(r, 0, 10);
  EXPECT_EQ(w.first, 0);
  EXPECT_EQ(w.last, 1);
  EXPECT_EQ(
      w.note,
      p + ":4: tendon contraction is NaN from t = 0.033 s; the window stops before it (0.0165 s instead of 10 s)");
  EXPECT_THROW_MESSAGE(
      MakeStarfishWindow(r, 0.03, 1), InvalidInputError,
      p + ":4: tendon contraction is NaN at the window's first row (t = 0.033 s): nothing to simulate");
}

TEST(CalibrateStarfishTest, WindowsOfTheRealRecordingStopBeforeTheMissingTendon) {
  const StarfishRecording r = ReadStarfishRecording(kCyclic1);
  const StarfishWindow ten = MakeStarfishWindow(r, 0, 10);
  EXPECT_EQ(ten.first, 0);
  EXPECT_EQ(ten.last, 600);  // 10 s of 60 Hz frames
  EXPECT_EQ(ten.note, "");
  const StarfishWindow late = MakeStarfishWindow(r, 30, 10);
  EXPECT_EQ(late.last, 2029);
  EXPECT_NE(late.note.find(":2032: tendon contraction is NaN"), std::string::npos) << late.note;
}

class StarfishSceneTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { scene_ = new Scene(StarfishCalibration().MakeScene()); }
  static void TearDownTestSuite() { delete scene_; }
  static Scene* scene_;
};
Scene* StarfishSceneTest::scene_ = nullptr;

TEST_F(StarfishSceneTest, CentralColumnHasYAndZFixedAndXFree) {
  const Mesh& mesh = scene_->mesh;
  EXPECT_GT(mesh.num_vertices(), 762);  // the OBJ's vertices plus interior points
  const std::set<int> fixed(scene_->dirichlet.dofs.begin(), scene_->dirichlet.dofs.end());
  int column = 0;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    const bool in = std::abs(mesh.vertices(1, i)) < 0.018 && std::abs(mesh.vertices(2, i)) < 0.018;
    column += in;
    EXPECT_FALSE(fixed.count(3 * i)) << "x of node " << i;
    EXPECT_EQ(fixed.count(3 * i + 1) == 1, in) << "y of node " << i;
    EXPECT_EQ(fixed.count(3 * i + 2) == 1, in) << "z of node " << i;
  }
  EXPECT_GT(column, 20);
  EXPECT_EQ(fixed.size(), 2u * column);
}

TEST_F(StarfishSceneTest, MarkersAreAtTheFactSheetsRestPositions) {
  const std::array<int, 4> v = StarfishCalibration::MarkerVertices(scene_->mesh);
  const Vec3 expected[4] = {
      {-0.52, -4.50, -69.64}, {-0.19, -10.63, -39.18}, {-0.19, -13.27, 34.80}, {-0.63, -4.50, 65.26}};
  for (int m = 0; m < 4; ++m)
    EXPECT_LT((scene_->mesh.vertices.col(v[m]) - 1e-3 * expected[m]).norm(), 1e-3) << "M" << m + 1;
}

TEST_F(StarfishSceneTest, FourMusclesAlongTheArmsInTheFlatFaceLayer) {
  ASSERT_EQ(scene_->muscles.size(), 4u);
  const Mesh& mesh = scene_->mesh;
  for (int m = 0; m < 4; ++m) {
    const Muscle& muscle = scene_->muscles[m];
    EXPECT_GT(muscle.elements.size(), 10u) << "muscle " << m;
    ASSERT_EQ(muscle.fibers.size(), 1u);
    const int along = m < 2 ? 2 : 1, across = m < 2 ? 1 : 2;
    EXPECT_EQ(muscle.fibers[0], m < 2 ? Vec3(0, 0, 1) : Vec3(0, 1, 0));
    for (int e : muscle.elements) {
      Vec3 c = Vec3::Zero();
      int on_face = 0;
      for (int a = 0; a < 4; ++a) {
        c += mesh.vertices.col(mesh.elements(a, e)) / 4;
        on_face += std::abs(mesh.vertices(0, mesh.elements(a, e))) <= 1e-3;
      }
      EXPECT_GE(on_face, 3) << "a muscle element has a face on the flat face";
      EXPECT_LE(std::abs(c(across)), 7.5e-3);
      EXPECT_GT((m % 2 ? 1 : -1) * c(along), 0.018);
    }
  }
  ASSERT_TRUE(scene_->hydrodynamics.has_value());
  EXPECT_EQ(scene_->hydrodynamics->triangles.cols(), 1520);  // the OBJ's triangles (TetGen's Y switch)
  EXPECT_FALSE(scene_->gravity.has_value());
  EXPECT_DOUBLE_EQ(scene_->material.density, 400);
}

TEST(StarfishActivationsTest, SlackLagAndLengthShapeTheActivation) {
  const double h = 0.01;
  std::vector<double> c(40, 0.0);
  for (int k = 5; k < 40; ++k) c[k] = 0.0179;
  // No slack, no lag: the fact sheet's a = 1 - c / 65 mm (above the 1 mm onset).
  std::vector<double> a = StarfishActivations(c, h, StarfishActuation{0, 0, 0.065}, nullptr);
  EXPECT_EQ(a[4], 1.0);
  EXPECT_NEAR(a[5], 1 - (0.0179 - 0.0005) / 0.065, 1e-14);
  // Slack: nothing below it; the lag: a first-order approach to the held value.
  a = StarfishActivations(c, h, StarfishActuation{0.005, 0.05, 0.04}, nullptr);
  EXPECT_EQ(a[4], 1.0);
  EXPECT_GT(a[5], a[8]);
  const double filtered = 0.0179 * (1 - std::pow(0.05 / (0.05 + h), 35));  // after 35 steps from 0
  EXPECT_NEAR(a[39], 1 - (filtered - 0.005 - 0.0005) / 0.04, 1e-12);
  for (int k = 6; k < 40; ++k) EXPECT_LE(a[k], a[k - 1]);
  // Derivatives vs central differences.
  for (int k = 0; k < 40; ++k) c[k] = 0.009 + 0.008 * std::sin(0.7 * k);
  const StarfishActuation at{0.004, 0.03, 0.05};
  std::vector<std::array<double, 4>> d;
  StarfishActivations(c, h, at, &d);
  const double e = 1e-7;
  double largest[3] = {0, 0, 0};
  for (int j = 0; j < 3; ++j) {
    StarfishActuation plus = at, minus = at;
    double* p[2] = {j == 0   ? &plus.slack
                    : j == 1 ? &plus.lag
                             : &plus.length,
                    j == 0   ? &minus.slack
                    : j == 1 ? &minus.lag
                             : &minus.length};
    *p[0] += e;
    *p[1] -= e;
    const std::vector<double> ap = StarfishActivations(c, h, plus, nullptr);
    const std::vector<double> am = StarfishActivations(c, h, minus, nullptr);
    for (int k = 0; k < 40; ++k) {
      EXPECT_NEAR(d[k][j], (ap[k] - am[k]) / (2 * e), 1e-6) << "parameter " << j << ", step " << k;
      largest[j] = std::max(largest[j], std::abs(d[k][j]));
    }
  }
  EXPECT_GT(largest[0], 1);    // 1/m
  EXPECT_GT(largest[1], 0.1);  // 1/s
  EXPECT_GT(largest[2], 1);    // 1/m
  for (int k = 0; k < 40; ++k) EXPECT_EQ(d[k][3], 0.0) << "no release lag";
  EXPECT_THROW_MESSAGE(StarfishActivations(c, h, StarfishActuation{0, -1, 0.065}, nullptr), InvalidInputError,
                       "tendon lag = -1 is invalid: must be finite and >= 0 (s)");
  EXPECT_THROW_MESSAGE(StarfishActivations(c, h, StarfishActuation{0, 0.03, 0.065, -1.0}, nullptr), InvalidInputError,
                       "tendon release_lag = -1 is invalid: must be finite and >= 0 (s)");
  EXPECT_THROW_MESSAGE(
      StarfishActivations({0.0, 0.0105}, h, StarfishActuation{0, 0, 0.005}, nullptr), InvalidInputError,
      "tendon: activation -1 < 0 (the filtered contraction exceeds slack + length: slack 0 m, length 0.005 m) "
      "at step 1");
}

// An asymmetric servo: a release follows release_lag, a pull the lag; the
// derivatives in lag and release_lag match central differences, each
// non-zero only through its own direction of motion.
TEST(StarfishActivationsTest, AReleaseFollowsTheReleaseLag) {
  const double h = 0.01;
  std::vector<double> c(60, 0.0);
  for (int k = 5; k < 30; ++k) c[k] = 0.0179;  // a pull, held, then a release at step 30
  StarfishActuation slow_release{0, 0.03, 0.065, 0.2}, fast_release{0, 0.03, 0.065, 0.001};
  const std::vector<double> symmetric = StarfishActivations(c, h, StarfishActuation{0, 0.03, 0.065}, nullptr);
  const std::vector<double> slow = StarfishActivations(c, h, slow_release, nullptr);
  const std::vector<double> fast = StarfishActivations(c, h, fast_release, nullptr);
  for (int k = 0; k < 30; ++k) {  // the pull: the same
    EXPECT_EQ(slow[k], symmetric[k]) << k;
    EXPECT_EQ(fast[k], symmetric[k]) << k;
  }
  EXPECT_LT(slow[35], symmetric[35]);  // still contracted
  EXPECT_GT(fast[31], symmetric[31]);  // released at once
  EXPECT_NEAR(fast[32], 1.0, 1e-3);
  for (int k = 0; k < 60; ++k) c[k] = 0.009 + 0.008 * std::sin(0.7 * k);
  const StarfishActuation at{0.004, 0.03, 0.05, 0.08};
  std::vector<std::array<double, 4>> d;
  StarfishActivations(c, h, at, &d);
  const double e = 1e-7;
  for (const int j : {1, 3}) {
    StarfishActuation plus = at, minus = at;
    if (j == 1) {
      plus.lag += e;
      minus.lag -= e;
    } else {
      *plus.release_lag += e;
      *minus.release_lag -= e;
    }
    const std::vector<double> ap = StarfishActivations(c, h, plus, nullptr);
    const std::vector<double> am = StarfishActivations(c, h, minus, nullptr);
    double largest = 0;
    for (int k = 0; k < 60; ++k) {
      EXPECT_NEAR(d[k][j], (ap[k] - am[k]) / (2 * e), 1e-6) << "parameter " << j << ", step " << k;
      largest = std::max(largest, std::abs(d[k][j]));
    }
    EXPECT_GT(largest, 0.1) << "parameter " << j;  // 1/s
  }
}

// A tendon contraction the tendon cannot take names the recording's file and
// row (the window's inputs are where a recording meets the actuation).
TEST(CalibrateStarfishTest, WindowInputsNameTheRowOfANegativeActivation) {
  const std::string p =
      WriteTemp("starfish_long_tendon.csv",
                kHeader + kRow0 + "16.5,1,1,2,3,4,5,6,7,8\n33,80,1,2,3,4,5,6,7,8\n50,0,1,2,3,4,5,6,7,8\n");
  const StarfishRecording r = ReadStarfishRecording(p);
  StarfishCalibration starfish;
  EXPECT_THROW_MESSAGE(
      starfish.WindowInputs(r, MakeStarfishWindow(r, 0, 10), StarfishActuation{}), InvalidInputError,
      p + ":4: tendon = 80 mm gives activation -0.223077 < 0 (the filtered contraction exceeds slack + length: "
          "slack 0 m, length 0.065 m)");
}

// The errors of the recording against itself are zero; a common x shift of
// every marker leaves the arm-relative error; the zero-motion baseline is the
// RMS displacement and the mean-displacement one is never worse (the mean is
// the best constant per marker).
TEST(StarfishMetricsTest, ErrorsAndBaselinesOfTheRealRecording) {
  const StarfishRecording r = ReadStarfishRecording(kCyclic2);
  const StarfishWindow w = MakeStarfishWindow(r, 0, 5);
  const StarfishDisplacements cap = CapturedDisplacements(r, w);
  ASSERT_EQ(static_cast<int>(cap.size()), w.num_frames());
  EXPECT_EQ(CompareDisplacements(cap, cap).rmse, 0.0);
  StarfishDisplacements shifted = cap;
  double sum = 0;
  for (size_t j = 1; j < cap.size(); ++j)
    for (int m = 0; m < 4; ++m) {
      shifted[j][m](0) += 0.003 * j / cap.size();
      sum += cap[j][m].squaredNorm();
    }
  const StarfishErrors e = CompareDisplacements(shifted, cap);
  EXPECT_GT(e.rmse, 1e-4);
  EXPECT_NEAR(e.arm_relative_rmse, 0, 1e-15);
  const StarfishBaselines b = BaselineErrors(cap);
  EXPECT_NEAR(b.zero_motion.rmse, std::sqrt(sum / (4.0 * (cap.size() - 1))), 1e-15);
  EXPECT_LT(b.mean_displacement.rmse, b.zero_motion.rmse);
  EXPECT_EQ(b.zero_motion.frames, w.num_frames() - 1);
  EXPECT_THROW_MESSAGE(
      CompareDisplacements(StarfishDisplacements(3), cap), InvalidInputError,
      "CompareDisplacements: 3 predicted frames against " + std::to_string(cap.size()) + " captured ones");
}

// The trace has a header and one row per frame: time, tendon in mm, the
// frame's first activation, then simulated and captured x, z per marker in mm.
TEST(StarfishTraceTest, OneRowPerFrameInMillimetres) {
  const StarfishRecording r = ReadStarfishRecording(kCyclic1);
  const StarfishWindow w = MakeStarfishWindow(r, 2, 0.05);
  ASSERT_EQ(w.num_frames(), 4);
  Rollout rollout;
  rollout.inputs.resize(6);
  for (int k = 0; k < 6; ++k) rollout.inputs[k].activation = VectorXd::Constant(4, 1 - 0.01 * k);
  const StarfishDisplacements cap = CapturedDisplacements(r, w);
  StarfishDisplacements sim = cap;
  sim[3][1] = Eigen::Vector2d(0.002, -0.001);
  const std::string path = WriteStarfishTrace(Scratch().path().string(), r, w, rollout, 2, sim, cap);
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].substr(0, 54), "time_s,tendon_mm,activation,M1_sim_x,M1_cap_x,M1_sim_z");
  std::vector<double> row;
  std::stringstream fields(lines[4]);
  for (std::string f; std::getline(fields, f, ',');) row.push_back(std::stod(f));
  ASSERT_EQ(row.size(), 19u);
  // The file has 6 significant digits.
  EXPECT_NEAR(row[0], r.time[w.last], 1e-5 * r.time[w.last]);
  EXPECT_NEAR(row[1], r.tendon[w.last] * 1e3, 1e-5 * r.tendon[w.last] * 1e3);
  EXPECT_NEAR(row[2], 0.95, 1e-12);  // the frame's first step, 3 * 2 capped at the last input
  EXPECT_NEAR(row[7], 2.0, 1e-9);    // M2 simulated x, mm
  EXPECT_NEAR(row[9], -1.0, 1e-9);   // M2 simulated z, mm
  EXPECT_NEAR(row[8], cap[3][1](0) * 1e3, 1e-5 * std::abs(cap[3][1](0) * 1e3) + 1e-9);
}

// The VTK output: every stride-th frame of the body (its displacement from
// the first state) and the four captured markers as points at the marker
// vertex's first position plus the captured x, z displacement; the trace's
// plot is a PNG (where gnuplot is installed).
TEST(StarfishTraceTest, VtkHasTheBodyAndTheCapturedMarkersAndThePlotIsAPng) {
  const StarfishRecording r = ReadStarfishRecording(kCyclic1);
  const StarfishWindow w = MakeStarfishWindow(r, 2, 0.1);
  ASSERT_EQ(w.num_frames(), 7);
  Mesh mesh;
  mesh.type = ElementType::kTet4;
  mesh.vertices = Eigen::Matrix3Xd::Identity(3, 4);
  mesh.vertices.col(3) = Vec3(0.1, 0.2, 0.3);
  mesh.elements.resize(4, 1);
  mesh.elements << 0, 1, 2, 3;
  const std::array<int, 4> vertices = {0, 1, 2, 3};
  std::vector<State> states(13);  // 2 steps per frame
  for (size_t k = 0; k < states.size(); ++k) {
    states[k].x = Eigen::Map<const VectorXd>(mesh.vertices.data(), 12);
    states[k].x(0) += 1e-3 * k;
  }
  const StarfishDisplacements cap = CapturedDisplacements(r, w);
  std::vector<double> times(r.time.begin() + w.first, r.time.begin() + w.last + 1);
  const std::string dir = Scratch().path().string();
  const std::array<std::string, 2> pvd = WriteStarfishVtk(dir, "c1", mesh, vertices, states, 2, times, cap, 3);
  EXPECT_EQ(pvd[0], dir + "/c1_body.pvd");
  EXPECT_EQ(pvd[1], dir + "/c1_markers.pvd");
  auto read = [](const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string markers = read(pvd[1]);
  EXPECT_NE(markers.find("c1_markers_0002.vtp"), std::string::npos);  // frames 0, 3, 6
  EXPECT_EQ(markers.find("c1_markers_0003.vtp"), std::string::npos);
  EXPECT_NE(read(pvd[0]).find("c1_body_0002.vtu"), std::string::npos);
  // Frame 6 (file 2): M4 at its vertex (0.1, 0.2, 0.3) plus the captured displacement.
  const std::string points = read(dir + "/c1_markers_0002.vtp");
  std::istringstream in(points.substr(points.find("format=\"ascii\">") + 15));
  Eigen::Matrix<double, 3, 4> p;
  for (int m = 0; m < 4; ++m) in >> p(0, m) >> p(1, m) >> p(2, m);
  EXPECT_NEAR(p(0, 3), 0.1 + cap[6][3](0), 1e-15);
  EXPECT_NEAR(p(1, 3), 0.2, 1e-15);
  EXPECT_NEAR(p(2, 3), 0.3 + cap[6][3](1), 1e-15);
  EXPECT_NEAR(p(0, 0), 1 + cap[6][0](0), 1e-15);
  EXPECT_THROW_MESSAGE(WriteStarfishVtk(dir, "c1", mesh, vertices, states, 2, times, cap, 0), InvalidInputError,
                       "stride = 0 is invalid: must be >= 1");
  EXPECT_THROW_MESSAGE(WriteStarfishVtk(dir, "c1", mesh, vertices, std::vector<State>(12, states[0]), 2, times, cap, 1),
                       InvalidInputError, "starfish vtk: 12 states are too few for 7 frames of 2 steps");
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot is not installed: the plot is not checked";
  Rollout rollout;
  rollout.inputs.resize(12);
  for (StepInput& in : rollout.inputs) in.activation = VectorXd::Ones(4);
  const std::string trace = WriteStarfishTrace(dir, r, w, rollout, 2, cap, cap);
  WriteStarfishTracePlot(trace, dir + "/c1.png", "c1");
  std::ifstream png(dir + "/c1.png", std::ios::binary);
  char magic[4] = {};
  png.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

// The window of the gradient and fit tests: 0.15 s from 1.15 s of cyclic1
// (the tendon first moves at 1.18 s), one step per frame.
class StarfishFitTest : public ::testing::Test {
 protected:
  StarfishFitTest() : recording_(ReadStarfishRecording(kCyclic1)), window_(MakeStarfishWindow(recording_, 1.15, 0.15)) {
    starfish_.set_substeps(1);
  }
  StarfishCalibration starfish_;
  StarfishRecording recording_;
  StarfishWindow window_;
};

TEST_F(StarfishFitTest, LossGradientMatchesCentralDifferences) {
  starfish_.set_fit_method(StarfishFitMethod::kLbfgs);
  SolverOptions options = starfish_.Options(Method::kPdLbfgs, 1);
  options.rel_tolerance = 1e-10;
  options.abs_tolerance = 1e-10;
  options.backward_rel_tolerance = 1e-11;
  const MaterialParameters material{2e5, 0.35, 400};
  const StarfishActuation actuation{0.004, 0.03, 0.05};
  auto model = starfish_.MakeModel(recording_, window_, options, material, actuation);
  auto loss = [&](const double* p, double* gradient) {
    const Eigen::Map<const VectorXd> point(p, 5);
    VectorXd g, value;
    if (!gradient) {
      EXPECT_TRUE(model->Evaluate(point, {0}, &value, nullptr)) << model->statistics().last_error;
      return value(0);
    }
    double cost = 0;
    EXPECT_TRUE(model->Gradient(point, VectorXd::Ones(1), &g, &cost)) << model->statistics().last_error;
    std::copy(g.data(), g.data() + g.size(), gradient);
    return cost;
  };
  const double p0[5] = {2e5, 0.35, 0.004, 0.03, 0.05};
  double g[5];
  const double l0 = loss(p0, g);
  EXPECT_GT(l0, 0);
  const double step[5] = {2e5 * 1e-4, 1e-4, 1e-6, 1e-5, 1e-6};
  const char* names[5] = {"dL/dE", "dL/dnu", "dL/dslack", "dL/dlag", "dL/dlength"};
  for (int i = 0; i < 5; ++i) {
    double pp[5], pm[5];
    std::copy(p0, p0 + 5, pp);
    std::copy(p0, p0 + 5, pm);
    pp[i] += step[i];
    pm[i] -= step[i];
    const double fd = (loss(pp, nullptr) - loss(pm, nullptr)) / (2 * step[i]);
    EXPECT_NEAR(g[i], fd, 1e-4 * std::abs(fd)) << names[i];
    EXPECT_GT(std::abs(fd) * p0[i], 1e-3 * l0) << names[i] << ": the loss does depend on it here";
  }
}

TEST_F(StarfishFitTest, BodyArmsRegionsGiveTheArmsTheirOwnYoungsModulus) {
  EXPECT_EQ(ParseStarfishRegions("body-arms"), StarfishRegions::kBodyArms);
  EXPECT_THROW_MESSAGE(ParseStarfishRegions("legs"), InvalidInputError,
                       "--regions = 'legs' is invalid: calibrate-starfish knows 'body-arms'");
  starfish_.set_regions(StarfishRegions::kBodyArms);
  starfish_.set_fit_method(StarfishFitMethod::kLbfgs);
  const Scene scene = starfish_.MakeScene();
  ASSERT_EQ(scene.material_regions.size(), 1u);
  const size_t arms = scene.material_regions[0].elements.size();
  EXPECT_GT(arms, scene.mesh.num_elements() / 2u);  // the arms are most of the body
  EXPECT_LT(arms, static_cast<size_t>(scene.mesh.num_elements()));
  for (const Muscle& m : scene.muscles)  // every muscle lies in an arm
    for (const int e : m.elements)
      EXPECT_TRUE(std::count(scene.material_regions[0].elements.begin(), scene.material_regions[0].elements.end(), e));
  // The model's material block {E, nu, E_arms, nu_arms}: the arms' gradient.
  SolverOptions options = starfish_.Options(Method::kPdLbfgs, 1);
  options.rel_tolerance = 1e-10;
  options.abs_tolerance = 1e-10;
  options.backward_rel_tolerance = 1e-11;
  auto model = starfish_.MakeModel(recording_, window_, options, MaterialParameters{2e5, 0.35, 400},
                                   StarfishActuation{0.004, 0.03, 0.05});
  ASSERT_EQ(model->num_blocks(), 2);
  ASSERT_EQ(model->block(0).size(), 4);
  ASSERT_EQ(model->block(1).size(), 3);
  auto loss = [&](const double* material, double* gradient) {
    VectorXd p(7), g;
    p << material[0], material[1], material[2], material[3], 0.004, 0.03, 0.05;
    if (!gradient) {
      VectorXd value;
      EXPECT_TRUE(model->Evaluate(p, {0}, &value, nullptr)) << model->statistics().last_error;
      return value(0);
    }
    double cost = 0;
    EXPECT_TRUE(model->Gradient(p, VectorXd::Ones(1), &g, &cost)) << model->statistics().last_error;
    std::copy(g.data(), g.data() + g.size(), gradient);
    return cost;
  };
  const double p0[4] = {2e5, 0.35, 1e5, 0.35};
  double g[7];
  loss(p0, g);
  for (const int i : {2, 3}) {
    const double step = i == 2 ? 1e5 * 1e-4 : 1e-4;
    double pp[4], pm[4];
    std::copy(p0, p0 + 4, pp);
    std::copy(p0, p0 + 4, pm);
    pp[i] += step;
    pm[i] -= step;
    const double fd = (loss(pp, nullptr) - loss(pm, nullptr)) / (2 * step);
    EXPECT_NEAR(g[i], fd, 1e-4 * std::abs(fd)) << "material block entry " << i;
  }
  // The fit: the arms' E moves apart from the body's and the loss drops.
  const StarfishFit fit =
      starfish_.Fit(recording_, window_, starfish_.Options(Method::kPdLbfgs, 1), MaterialParameters{5e5, 0.4, 400},
                    StarfishCalibration::ActuationGuess(), 2, nullptr);
  EXPECT_TRUE(fit.usable) << fit.termination;
  ASSERT_EQ(fit.region_materials.size(), 1u);
  EXPECT_NE(fit.region_materials[0].youngs_modulus, fit.material.youngs_modulus);
  EXPECT_EQ(fit.region_materials[0].poissons_ratio, fit.material.poissons_ratio);
  EXPECT_LT(fit.final_cost, fit.initial_cost);
  EXPECT_EQ(fit.statistics.failures, 0) << fit.statistics.last_error;
}

// The fit's bounds are the manifold's: a huge step stays inside them, E,
// nu, lag and length move relatively, and a start outside is refused.
TEST_F(StarfishFitTest, FitCoordinatesKeepTheBoundsAndRefuseStartsOutside) {
  const std::vector<double> x =
      StarfishFitStart(MaterialParameters{5e5, 0.4, 400}, StarfishActuation{0.003, 0.05, 0.065}, false);
  ASSERT_EQ(x, (std::vector<double>{5e5, 0.4, 0.003, 0.05, 0.065}));
  const solvers::CoordinateManifold manifold(StarfishFitCoordinates(false));
  ASSERT_EQ(manifold.AmbientSize(), 5);
  const double low[5] = {-60, 60, -60, 60, -60}, high[5] = {60, -60, 60, -60, 60};
  double y[5];
  ASSERT_TRUE(manifold.Plus(x.data(), low, y));
  EXPECT_NEAR(y[0], 1e4, 1e-6);
  EXPECT_NEAR(y[1], 0.45, 1e-12);
  EXPECT_NEAR(y[2], 0, 1e-15);
  EXPECT_NEAR(y[3], 0.5, 1e-12);
  EXPECT_NEAR(y[4], 0.03, 1e-12);
  ASSERT_TRUE(manifold.Plus(x.data(), high, y));
  EXPECT_NEAR(y[0], 5e6, 1e-3);
  EXPECT_NEAR(y[1], 0.2, 1e-12);
  EXPECT_NEAR(y[2], 0.015, 1e-15);
  EXPECT_NEAR(y[3], 1e-3, 1e-12);
  EXPECT_NEAR(y[4], 0.13, 1e-12);
  EXPECT_EQ(StarfishFitCoordinates(true).size(), 6u);
  EXPECT_EQ(StarfishFitStart(MaterialParameters{5e5, 0.4, 400}, StarfishActuation{0.003, 0.05, 0.065}, true).back(),
            5e5);
  EXPECT_THROW_MESSAGE(
      StarfishFitStart(MaterialParameters{6e6, 0.4, 400}, StarfishActuation{0.003, 0.05, 0.065}, false),
      InvalidInputError, "youngs_modulus = 6e+06 is outside the fit's interval (1e4, 5e6) Pa");
  EXPECT_THROW_MESSAGE(StarfishFitStart(MaterialParameters{5e5, 0.4, 400}, StarfishActuation{0.02, 0.05, 0.065}, false),
                       InvalidInputError, "tendon slack = 0.02 is outside the fit's interval (0, 0.015) m");
}

TEST_F(StarfishFitTest, ShortFitLowersTheLoss) {
  starfish_.set_fit_method(StarfishFitMethod::kLbfgs);
  const StarfishFit fit =
      starfish_.Fit(recording_, window_, starfish_.Options(Method::kPdLbfgs, 1), MaterialParameters{5e5, 0.4, 400},
                    StarfishCalibration::ActuationGuess(), 3, nullptr);
  EXPECT_TRUE(fit.usable) << fit.termination;
  EXPECT_GE(fit.iterations, 1);
  EXPECT_LT(fit.final_cost, 0.9 * fit.initial_cost);
  EXPECT_GT(fit.statistics.gradients, 0);
  EXPECT_EQ(fit.statistics.failures, 0) << fit.statistics.last_error;
}

// The least-squares model's residual Jacobian (forward-mode tangents through
// the water's drag, and for the water's coefficients through the state
// forces) against central differences of the residuals.
TEST_F(StarfishFitTest, ResidualJacobianMatchesCentralDifferences) {
  ASSERT_EQ(starfish_.fit_method(), StarfishFitMethod::kLevenbergMarquardt);
  ASSERT_TRUE(starfish_.water_in_model());
  ASSERT_TRUE(starfish_.density_in_model());  // the default; its column is checked below, with the damping's
  starfish_.set_fit_density(false);
  SolverOptions options = starfish_.Options(Method::kPdLbfgs, 1);
  options.rel_tolerance = 1e-10;
  options.abs_tolerance = 1e-10;
  const StarfishWater water{0.1, 1.5, 0.3};
  auto model = starfish_.MakeModel(recording_, window_, options, MaterialParameters{2e5, 0.35, 400},
                                   StarfishActuation{0.004, 0.03, 0.05}, water);
  ASSERT_EQ(model->num_blocks(), 3);
  ASSERT_EQ(model->ResolvedMode(model->num_rows()), solvers::DerivativeMode::kForward);
  VectorXd p0(8);
  p0 << 2e5, 0.35, 0.004, 0.03, 0.05, 0.1, 1.5, 0.3;
  MatrixXd j;
  ASSERT_TRUE(model->Evaluate(p0, model->AllRows(), nullptr, &j)) << model->statistics().last_error;
  EXPECT_EQ(model->statistics().tangent_passes, 1);
  const double step[8] = {2e5 * 1e-4, 1e-4, 1e-6, 1e-5, 1e-6, 1e-5, 1e-4, 1e-4};
  for (int i = 0; i < 8; ++i) {
    VectorXd plus = p0, minus = p0, rp, rm;
    plus(i) += step[i];
    minus(i) -= step[i];
    ASSERT_TRUE(model->Evaluate(plus, model->AllRows(), &rp, nullptr));
    ASSERT_TRUE(model->Evaluate(minus, model->AllRows(), &rm, nullptr));
    const VectorXd fd = (rp - rm) / (2 * step[i]);
    EXPECT_GT(fd.norm() * std::abs(p0(i)), i < 5 ? 1e-3 : 1e-6) << "column " << i << ": the residuals depend on it";
    EXPECT_LT((j.col(i) - fd).norm(), 1e-4 * fd.norm()) << "column " << i;
  }
  // Without the water in the model: 5 columns, the scene has `water`.
  starfish_.set_fit_water(false);
  auto fixed = starfish_.MakeModel(recording_, window_, options, MaterialParameters{2e5, 0.35, 400},
                                   StarfishActuation{0.004, 0.03, 0.05}, water);
  ASSERT_EQ(fixed->num_blocks(), 2);
  VectorXd r8, r5;
  ASSERT_TRUE(model->Evaluate(p0, model->AllRows(), &r8, nullptr));
  ASSERT_TRUE(fixed->Evaluate(p0.head(5), fixed->AllRows(), &r5, nullptr));
  EXPECT_LT((r8 - r5).norm(), 1e-9 * r8.norm());
}

// With the density and a linear damping fitted too: the material block is
// {E, nu, density}, a last block {linear_damping}; their Jacobian columns
// (forward-mode tangents through the mass matrix and the damping force)
// against central differences of the residuals; starts outside their
// intervals are refused.
TEST_F(StarfishFitTest, DensityAndDampingJacobianMatchesCentralDifferences) {
  starfish_.set_fit_density(true);
  starfish_.set_fit_damping(true);
  ASSERT_TRUE(starfish_.density_in_model() && starfish_.damping_in_model());
  SolverOptions options = starfish_.Options(Method::kPdLbfgs, 1);
  options.rel_tolerance = 1e-10;
  options.abs_tolerance = 1e-10;
  auto model = starfish_.MakeModel(recording_, window_, options, MaterialParameters{2e5, 0.35, 600},
                                   StarfishActuation{0.004, 0.03, 0.05}, StarfishWater{0.1, 1.5, 0.3}, nullptr, 2.0);
  ASSERT_EQ(model->num_blocks(), 4);
  ASSERT_EQ(model->block(0).size(), 3);
  ASSERT_EQ(model->block(3).size(), 1);
  VectorXd p0(10);
  p0 << 2e5, 0.35, 600, 0.004, 0.03, 0.05, 0.1, 1.5, 0.3, 2.0;
  MatrixXd j;
  ASSERT_TRUE(model->Evaluate(p0, model->AllRows(), nullptr, &j)) << model->statistics().last_error;
  ASSERT_EQ(j.cols(), 10);
  for (const int i : {2, 9}) {  // density, linear_damping
    const double step = i == 2 ? 600 * 1e-4 : 1e-4;
    VectorXd plus = p0, minus = p0, rp, rm;
    plus(i) += step;
    minus(i) -= step;
    ASSERT_TRUE(model->Evaluate(plus, model->AllRows(), &rp, nullptr));
    ASSERT_TRUE(model->Evaluate(minus, model->AllRows(), &rm, nullptr));
    const VectorXd fd = (rp - rm) / (2 * step);
    EXPECT_GT(fd.norm() * std::abs(p0(i)), 1e-4) << "column " << i << ": the residuals depend on it";
    EXPECT_LT((j.col(i) - fd).norm(), 1e-4 * fd.norm()) << "column " << i;
  }
  EXPECT_EQ(StarfishFitNames(true, true, true, true),
            (std::vector<std::string>{"youngs_modulus", "poissons_ratio", "density", "tendon_slack", "tendon_lag",
                                      "tendon_length", "tendon_release_lag", "drag_tangential", "drag_normal", "thrust",
                                      "linear_damping"}));
  StarfishMassDamping md;
  md.fit_density = true;
  EXPECT_THROW_MESSAGE(CheckStarfishMassDampingStart(9000, md), InvalidInputError,
                       "density = 9000 is outside the fit's interval (50, 5000) kg/m^3");
  md.fit_density = false;
  md.linear_damping_guess = 200;
  EXPECT_THROW_MESSAGE(CheckStarfishMassDampingStart(9000, md), InvalidInputError,
                       "linear_damping = 200 is outside the fit's interval (0.01, 100) 1/s");
  // A one-iteration fit reports both values, the density in the material.
  starfish_.set_fit_release_lag(false);
  const StarfishFit fit =
      starfish_.Fit(recording_, window_, starfish_.Options(Method::kPdLbfgs, 1), MaterialParameters{5e5, 0.4, 400},
                    StarfishCalibration::ActuationGuess(), 1, nullptr);
  EXPECT_TRUE(fit.usable) << fit.termination;
  EXPECT_TRUE(fit.density_fitted);
  ASSERT_TRUE(fit.linear_damping.has_value());
  EXPECT_EQ(StarfishFitValues(fit).size(), 10u);
  EXPECT_EQ(fit.standard_deviation.size(), 10u);
  EXPECT_LE(fit.final_cost, fit.initial_cost);
}

// Levenberg-Marquardt lowers the cost and gives every parameter a finite
// standard deviation and a symmetric correlation matrix with unit diagonal.
// (The test window has no release: the release lag is not fitted here.)
TEST_F(StarfishFitTest, LeastSquaresFitLowersTheCostAndHasIntervals) {
  ASSERT_TRUE(starfish_.fit_release_lag());  // the default
  starfish_.set_fit_release_lag(false);
  starfish_.set_fit_density(false);  // 8 values: E, nu, slack, lag, length and the water's three
  const StarfishFit fit =
      starfish_.Fit(recording_, window_, starfish_.Options(Method::kPdLbfgs, 1), MaterialParameters{5e5, 0.4, 400},
                    StarfishCalibration::ActuationGuess(), 3, nullptr);
  EXPECT_TRUE(fit.usable) << fit.termination;
  EXPECT_LT(fit.final_cost, 0.9 * fit.initial_cost);
  EXPECT_GT(fit.statistics.tangent_passes, 0);
  EXPECT_EQ(fit.statistics.adjoint_passes, 0);
  EXPECT_EQ(fit.residuals, 8 * (window_.num_frames() - 1));
  EXPECT_TRUE(fit.water_fitted);
  ASSERT_EQ(fit.standard_deviation.size(), 8u);
  ASSERT_EQ(fit.correlation.size(), 64u);
  for (int i = 0; i < 8; ++i) {
    EXPECT_TRUE(std::isfinite(fit.standard_deviation[i]) && fit.standard_deviation[i] > 0) << i;
    EXPECT_NEAR(fit.correlation[9 * i], 1, 1e-9);
    for (int k = 0; k < 8; ++k) EXPECT_NEAR(fit.correlation[8 * i + k], fit.correlation[8 * k + i], 1e-12);
  }
  EXPECT_THROW_MESSAGE(CheckStarfishWaterStart(StarfishWater{0.05, 30, 0}), InvalidInputError,
                       "drag_normal = 30 is outside the fit's interval (0.2, 20)");
  starfish_.set_regions(StarfishRegions::kBodyArms);
  EXPECT_THROW_MESSAGE(
      starfish_.Fit(recording_, window_, starfish_.Options(Method::kPdLbfgs, 1), MaterialParameters{5e5, 0.4, 400},
                    StarfishCalibration::ActuationGuess(), 3, nullptr),
      InvalidInputError, "the lm fit has no tied arms' nu: fit body-arms regions with --fit lbfgs");
  EXPECT_THROW_MESSAGE(ParseStarfishFitMethod("newton"), InvalidInputError,
                       "--fit = 'newton' is invalid: calibrate-starfish fits with 'lm' or 'lbfgs'");
}

}  // namespace
}  // namespace diffpd::problems
