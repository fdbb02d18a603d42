// Captured-motion files (diffpd/captured_motion.h): round trip, every
// rejection message with file and line, marker stencils on tets and hexes,
// and the time interpolation of simulated trajectories.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "diffpd/captured_motion.h"
#include "diffpd/error.h"
#include "util/expect_message.h"
#include "test_scenes.h"
#include "util/temporary_directory.h"

namespace diffpd {
namespace {

// A file in this program's own temporary directory (removed at exit).
std::string TempPath(const std::string& name) {
  static const testing::TemporaryDirectory directory("diffpd-captured-motion");
  return directory.File(name);
}

std::string WriteText(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  std::ofstream(path) << text;
  return path;
}

// The message of the InvalidInputError thrown by reading `text`.
std::string ReadError(const std::string& text) {
  const std::string path = WriteText("bad.csv", text);
  try {
    ReadCapturedMotion(path);
  } catch (const InvalidInputError& e) {
    std::string m = e.what();
    const size_t at = m.find(path);
    if (at == 0) m.replace(0, path.size(), "F");
    return m;
  }
  return "no exception";
}

const char* kMarkers = "# test\nmarker,0,vertex,1\nmarker,1,element,0,0.2,0.3,0.1\n";

TEST(CapturedMotionTest, WriteThenReadRoundTripsExactly) {
  CapturedMotion motion;
  motion.markers.push_back(Marker{0, 3, -1, Vec3::Zero(), 0});
  motion.markers.push_back(Marker{4, -1, 2, Vec3(0.1, 0.2, 1.0 / 3.0), 0});
  motion.samples.push_back(MarkerSample{0.0, 0, Vec3(0.1, 0.2, 0.3), Vec3::Ones(), 0});
  motion.samples.push_back(MarkerSample{0.01, 4, Vec3(1.0 / 7.0, -2e-5, 3.3), Vec3(1, 0, 2.5), 0});
  motion.samples.push_back(MarkerSample{0.02, 0, Vec3(0.4, 0.5, 0.6), Vec3::Ones(), 0});
  const std::string path = TempPath("roundtrip.csv");
  WriteCapturedMotion(path, motion, "synthetic\nseed 3");
  const CapturedMotion read = ReadCapturedMotion(path);
  ASSERT_EQ(read.markers.size(), 2u);
  ASSERT_EQ(read.samples.size(), 3u);
  EXPECT_EQ(read.markers[1].id, 4);
  EXPECT_EQ(read.markers[1].element, 2);
  EXPECT_EQ(read.markers[1].local, motion.markers[1].local);
  EXPECT_EQ(read.markers[0].line, 3);  // after the two comment lines
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(read.samples[i].time, motion.samples[i].time);
    EXPECT_EQ(read.samples[i].marker, motion.samples[i].marker);
    EXPECT_EQ(read.samples[i].position, motion.samples[i].position);
    EXPECT_EQ(read.samples[i].weight, motion.samples[i].weight);
  }
  EXPECT_EQ(read.samples[0].line, 6);
  EXPECT_DOUBLE_EQ(read.end_time(), 0.02);
  EXPECT_EQ(read.FindMarker(4), &read.markers[1]);
  EXPECT_EQ(read.FindMarker(1), nullptr);
}

TEST(CapturedMotionTest, AcceptsSpacesBlankLinesAndInterleavedMarkers) {
  const CapturedMotion m = ReadCapturedMotion(WriteText(
      "ok.csv",
      std::string(kMarkers) + "\n time , marker , x , y , z \n0, 1, 1, 2, 3\n0, 0, 1, 2, 3\n\n0.5,0,1,2,3\n"));
  EXPECT_EQ(m.samples.size(), 3u);
  EXPECT_EQ(m.samples[2].weight, Vec3::Ones());
}

// One bad captured-motion file: its text and the exact message, with the
// file's path replaced by "F".
struct BadFile {
  std::string text;
  std::string message;
};

const std::string kHeader = std::string(kMarkers) + "time,marker,x,y,z\n";  // header on line 4
const std::string kWeightHeader = std::string(kMarkers) + "time,marker,x,y,z,wx,wy,wz\n";

const BadFile kBadFiles[] = {
    {std::string(kMarkers) + "marker,2,vertex\n",
     "F:4: expected 'marker,<id>,vertex,<v>' or 'marker,<id>,element,<e>,<c0>,<c1>,<c2>', got 'marker,2,vertex'"},
    {std::string(kMarkers) + "marker,1,vertex,3\ntime,marker,x,y,z\n0,0,1,2,3\n",
     "F:4: marker id 1 is declared twice (first on line 3)"},
    {"marker,-2,vertex,3\n", "F:1: marker id -2 is invalid: must be an integer >= 0"},
    {"marker,2,vertex,-3\n", "F:1: vertex index -3 is invalid: must be an integer >= 0"},
    {kHeader + "marker,5,vertex,0\n", "F:5: marker declarations must come before the header"},
    {std::string(kMarkers) + "0,1,2,3,4\n",
     "F:4: expected the header 'time,marker,x,y,z' or 'time,marker,x,y,z,wx,wy,wz', got '0,1,2,3,4'"},
    {kHeader + "0,0,1,2\n", "F:5: expected 5 fields (time,marker,x,y,z), got 4"},
    {kWeightHeader + "0,0,1,2,3\n", "F:5: expected 8 fields (time,marker,x,y,z,wx,wy,wz), got 5"},
    {kHeader + "0,0,abc,2,3\n", "F:5: x is not a number: 'abc'"},
    {kHeader + "0,0,1,,3\n", "F:5: y is not a number: ''"},
    {kHeader + "0,1.5,1,2,3\n", "F:5: marker is not an integer: '1.5'"},
    {kHeader + "0,0,1,inf,3\n", "F:5: y = inf is not finite"},
    {kHeader + "nan,0,1,2,3\n", "F:5: time = nan is not finite"},
    {kHeader + "-0.1,0,1,2,3\n", "F:5: time = -0.1 is invalid: must be >= 0 (s)"},
    {kHeader + "0,0,1e300,2,3\n", "F:5: x = 1e+300 is invalid: must be within +-1000000 (m)"},
    {kHeader + "0,0,1,2,-1000001\n", "F:5: z = -1000001 is invalid: must be within +-1000000 (m)"},
    {kWeightHeader + "0,0,1,2,3,1,1,-1\n", "F:5: wz = -1 is invalid: weights must be >= 0"},
    {kWeightHeader + "0,0,1,2,3,1e300,1,1\n", "F:5: wx = 1e+300 is invalid: weights must be <= 1000000000000 (1/m)"},
    {kHeader + "0,9,1,2,3\n", "F:5: unknown marker id 9 (declared ids: 0, 1)"},
    {kHeader + "0.2,0,1,2,3\n0.1,1,1,2,3\n0.1,0,1,2,3\n",
     "F:7: time 0.1 of marker 0 is not after its previous sample at time 0.2 (line 5): times must increase "
     "strictly per marker"},
    {kHeader + "0.2,0,1,2,3\n0.2,0,1,2,3\n",
     "F:6: time 0.2 of marker 0 is not after its previous sample at time 0.2 (line 5): times must increase "
     "strictly per marker"},
    {"# nothing\ntime,marker,x,y,z\n", "F: no marker declared"},
    {kHeader, "F: no samples"},
    {std::string(kMarkers), "F: no samples"},
};

TEST(CapturedMotionTest, RejectsBadFilesNamingLineAndProblem) {
  for (const BadFile& bad : kBadFiles) EXPECT_EQ(ReadError(bad.text), bad.message) << bad.text;
}

TEST(CapturedMotionTest, RejectsPathsThatAreNotReadableFiles) {
  const std::string dir = TempPath("directory");
  std::filesystem::create_directories(dir);
  const std::pair<std::string, std::string> cases[] = {
      {"/nonexistent/m.csv", "cannot open '/nonexistent/m.csv'"},
      {dir, "cannot open '" + dir + "': it is a directory, not a file"},
  };
  for (const auto& [path, message] : cases) {
    EXPECT_THROW_MESSAGE(ReadCapturedMotion(path), InvalidInputError, message);
  }
}

TEST(CapturedMotionTest, ValidateReportsRecordsNotFromAFileWithoutLine) {
  CapturedMotion motion;
  motion.markers.push_back(Marker{0, 3, -1, Vec3::Zero(), 0});
  motion.samples.push_back(MarkerSample{0.1, 0, Vec3::Zero(), Vec3::Ones(), 0});
  motion.samples.push_back(MarkerSample{0.1, 0, Vec3::Zero(), Vec3::Ones(), 0});
  try {
    motion.Validate("capture");
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(),
                 "capture: time 0.1 of marker 0 is not after its previous sample at time 0.1: times must increase "
                 "strictly per marker");
  }
  motion.samples.pop_back();
  motion.markers.push_back(Marker{1, 2, 4, Vec3::Zero(), 0});
  try {
    motion.Validate("capture");
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "capture: marker 1: must be a vertex or an element point");
  }
}

// Positions under an affine map x -> A x + b are reproduced exactly by
// stencils of points inside tets and hexes (both interpolate affine fields).
TEST(CapturedMotionTest, StencilsInterpolateAffineMotionExactly) {
  Mat3 a;
  a << 1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2;
  const Vec3 b(0.3, -0.2, 0.1);
  for (bool tets : {false, true}) {
    const Mesh mesh = tets ? testing::BoxTetMesh(2, 1, 1, 0.2, 0.1, 0.1) : testing::BoxHexMesh(2, 1, 1, 0.2, 0.1, 0.1);
    Marker m;
    m.element = 1;
    m.local = tets ? Vec3(0.2, 0.3, 0.1) : Vec3(-0.5, 0.25, 0.9);
    const auto stencil = MarkerStencil(m, mesh);
    double sum = 0;
    Vec3 rest = Vec3::Zero(), moved = Vec3::Zero();
    for (const auto& [node, w] : stencil) {
      sum += w;
      rest += w * mesh.vertices.col(node);
      moved += w * (a * mesh.vertices.col(node) + b);
    }
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_LT((moved - (a * rest + b)).norm(), 1e-15);
    if (!tets) {  // trilinear map: local coordinates are the scaled offsets within the cell
      const Vec3 lo = mesh.vertices.col(mesh.elements(0, 1)), hi = mesh.vertices.col(mesh.elements(7, 1));
      EXPECT_LT((rest - (lo + (hi - lo).cwiseProduct((m.local + Vec3::Ones()) / 2))).norm(), 1e-15);
    }
  }
}

TEST(CapturedMotionTest, StencilRejectsOutOfRangeMarkers) {
  const Mesh tet = testing::BoxTetMesh(1, 1, 1, 0.1, 0.1, 0.1);
  const Mesh hex = testing::BoxHexMesh(1, 1, 1, 0.1, 0.1, 0.1);
  auto message = [](const Marker& m, const Mesh& mesh) {
    try {
      MarkerStencil(m, mesh);
    } catch (const InvalidInputError& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_EQ(message(Marker{3, 99, -1, Vec3::Zero(), 0}, hex),
            "marker 3: vertex 99 is out of range (the mesh has 8 vertices)");
  EXPECT_EQ(message(Marker{3, -1, 12, Vec3::Zero(), 0}, tet),
            "marker 3: element 12 is out of range (the mesh has 6 elements)");
  EXPECT_EQ(message(Marker{3, -1, 0, Vec3(0.5, 0.6, 0.1), 0}, tet),
            "marker 3: barycentric coordinates (0.5, 0.6, 0.1) are outside the tetrahedron (need b >= 0 and b1 + "
            "b2 + b3 <= 1)");
  EXPECT_EQ(message(Marker{3, -1, 0, Vec3(1.5, 0, 0), 0}, hex),
            "marker 3: local coordinates (1.5, 0, 0) are outside the reference hexahedron [-1, 1]^3");
  EXPECT_EQ(message(Marker{3, -1, -1, Vec3::Zero(), 0}, hex), "marker 3: must be a vertex or an element point");
  EXPECT_EQ(message(Marker{3, -1, 0, Vec3(1, 0, 0), 0}, tet), "no exception");  // on a face: accepted
}

TEST(CapturedMotionTest, ObservationsInterpolateLinearlyBetweenSteps) {
  const Mesh mesh = testing::BoxHexMesh(1, 1, 1, 0.1, 0.1, 0.1);
  CapturedMotion motion;
  motion.markers.push_back(Marker{7, 5, -1, Vec3::Zero(), 0});
  motion.samples.push_back(MarkerSample{0.025, 7, Vec3(1, 1, 1), Vec3(2, 1, 0), 0});
  motion.samples.push_back(MarkerSample{0.03, 7, Vec3(1, 1, 1), Vec3::Ones(), 0});
  motion.samples.push_back(MarkerSample{0.04, 7, Vec3::Zero(), Vec3::Ones(), 0});
  const int steps = MarkerObservations::RequiredSteps(motion, 0.01);
  EXPECT_EQ(steps, 4);
  const MarkerObservations obs(motion, mesh, 0.01, steps);
  std::vector<State> states(steps + 1);
  for (int k = 0; k <= steps; ++k) {
    states[k].x = VectorXd::Constant(mesh.num_dofs(), 10.0 * k);
    states[k].x.segment<3>(15) = Vec3(k, 2 * k, 3 * k);
  }
  EXPECT_LT((obs.Simulated(0, states) - Vec3(2.5, 5, 7.5)).norm(), 1e-12);
  EXPECT_EQ(obs.terms(0).size(), 2u);
  EXPECT_EQ(obs.last_step(0), 3);
  EXPECT_EQ(obs.terms(1).size(), 1u);  // 0.03 / 0.01 lands on step 3 up to rounding
  EXPECT_EQ(obs.last_step(1), 3);
  EXPECT_LT((obs.Simulated(1, states) - Vec3(3, 6, 9)).norm(), 1e-12);
  const VectorXd r = obs.Residuals(states);
  EXPECT_NEAR(r(0), 2 * 1.5, 1e-12);
  EXPECT_NEAR(r(1), 4.0, 1e-12);
  EXPECT_EQ(r(2), 0.0);
  EXPECT_EQ(obs.last_step(2), 4);
  try {
    MarkerObservations(motion, mesh, 0.01, 3);
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "sample 2: time 0.04 s is after the end of the simulation (3 steps of 0.01 s = 0.03 s)");
  }
}

// A motion of marker 0 (vertex 5) sampled at `times`; `line` > 0 marks the
// samples as read from a file, from that line on.
CapturedMotion VertexMotion(const std::vector<double>& times, int line = 0) {
  CapturedMotion motion;
  motion.markers.push_back(Marker{0, 5, -1, Vec3::Zero(), 0});
  for (size_t i = 0; i < times.size(); ++i)
    motion.samples.push_back(
        MarkerSample{times[i], 0, Vec3::Zero(), Vec3::Ones(), line > 0 ? line + static_cast<int>(i) : 0});
  return motion;
}

// Sample times a simulation cannot reach, and time steps that are no time
// steps, are refused by RequiredSteps with the exact message (never an
// integer overflow, never a rollout of millions of steps).
TEST(CapturedMotionTest, RequiredStepsRefusesTimesBeyondTheStepLimit) {
  struct Case {
    std::vector<double> times;
    int line;
    double time_step;
    std::string message;
  };
  const Case cases[] = {
      {{0.1, 1e300},
       0,
       0.01,
       "sample 1: time 1e+300 s needs 1e+302 steps of 0.01 s, more than the limit of 100000 "
       "(MarkerObservations::kMaxSteps)"},
      {{1e4},
       9,
       0.002,
       "line 9: time 10000 s needs 5e+06 steps of 0.002 s, more than the limit of 100000 "
       "(MarkerObservations::kMaxSteps)"},
      {{0.5}, 0, 0.0, "time step = 0 is invalid: must be finite and > 0 (s)"},
      {{0.5}, 0, std::nan(""), "time step = nan is invalid: must be finite and > 0 (s)"},
      {{0.5}, 0, -0.01, "time step = -0.01 is invalid: must be finite and > 0 (s)"},
  };
  for (const Case& c : cases) {
    EXPECT_THROW_MESSAGE(MarkerObservations::RequiredSteps(VertexMotion(c.times, c.line), c.time_step),
                         InvalidInputError, c.message);
  }
  EXPECT_EQ(MarkerObservations::RequiredSteps(VertexMotion({0.0, 1000.0}), 0.01), MarkerObservations::kMaxSteps);
}

// A sample far beyond the rollout's end is "after the end", however large
// its time (it once became step INT_MIN and crashed Simulated).
TEST(CapturedMotionTest, ObservationsRefuseSamplesAfterTheEndWithoutOverflow) {
  const Mesh mesh = testing::BoxHexMesh(1, 1, 1, 0.1, 0.1, 0.1);
  struct Case {
    std::vector<double> times;
    int line;
    int num_steps;
    std::string message;
  };
  const Case cases[] = {
      {{0.0, 1e300}, 0, 10, "sample 1: time 1e+300 s is after the end of the simulation (10 steps of 0.01 s = 0.1 s)"},
      {{3e9}, 4, 10, "line 4: time 3e+09 s is after the end of the simulation (10 steps of 0.01 s = 0.1 s)"},
      {{0.0}, 0, -1, "number of steps = -1 is invalid: must be >= 0"},
  };
  for (const Case& c : cases) {
    EXPECT_THROW_MESSAGE(MarkerObservations(VertexMotion(c.times, c.line), mesh, 0.01, c.num_steps), InvalidInputError,
                         c.message);
  }
}

TEST(CapturedMotionTest, SampleMarkersAddsSeededGaussianNoise) {
  const Mesh mesh = testing::BoxHexMesh(2, 2, 2, 0.1, 0.1, 0.1);
  std::vector<State> states(11);
  for (int k = 0; k <= 10; ++k) {
    states[k].x = Eigen::Map<const VectorXd>(mesh.vertices.data(), mesh.num_dofs()) * (1 + 0.01 * k);
    states[k].v = VectorXd::Zero(mesh.num_dofs());
  }
  std::vector<Marker> markers;
  for (int v = 0; v < mesh.num_vertices(); ++v) markers.push_back(Marker{v, v, -1, Vec3::Zero(), 0});
  markers.push_back(Marker{100, -1, 3, Vec3(0.1, -0.2, 0.3), 0});
  std::vector<double> times;
  for (int f = 0; f <= 40; ++f) times.push_back(0.0025 * f);  // 4 frames per step of 0.01 s
  const CapturedMotion exact = SampleMarkers(mesh, states, 0.01, markers, times);
  const MarkerObservations obs(exact, mesh, 0.01, 10);
  EXPECT_LT(obs.Residuals(states).norm(), 1e-15);
  EXPECT_EQ(exact.samples.size(), times.size() * markers.size());
  EXPECT_EQ(exact.samples[1].marker, 1);
  EXPECT_EQ(exact.samples[markers.size()].time, 0.0025);
  const double sigma = 1e-3;
  const CapturedMotion noisy = SampleMarkers(mesh, states, 0.01, markers, times, sigma, 42);
  const CapturedMotion again = SampleMarkers(mesh, states, 0.01, markers, times, sigma, 42);
  const CapturedMotion other = SampleMarkers(mesh, states, 0.01, markers, times, sigma, 43);
  const VectorXd r = obs.Residuals(states) - MarkerObservations(noisy, mesh, 0.01, 10).Residuals(states);
  const double n = static_cast<double>(r.size());  // 3 x 41 x 28 = 3444 draws
  EXPECT_LT(std::abs(r.mean()), 4 * sigma / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(r.squaredNorm() / n), sigma, 0.05 * sigma);
  EXPECT_EQ(noisy.samples[7].position, again.samples[7].position);
  EXPECT_NE(noisy.samples[7].position, other.samples[7].position);
  try {
    SampleMarkers(mesh, states, 0.01, markers, times, -1.0);
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "noise = -1 is invalid: must be finite and >= 0 (m)");
  }
}

}  // namespace
}  // namespace diffpd
