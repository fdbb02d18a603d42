// Captured motion: material points (markers) tracked over time, e.g. by a
// motion-capture system or a video tracker, the data of calibration.
//
// File format (CSV, one record per line; fields separated by ',', spaces
// around fields ignored; blank lines and lines starting with '#' ignored):
//
//   # any comment
//   marker,0,vertex,17                     marker 0 is mesh vertex 17
//   marker,1,element,5,0.2,0.3,0.1         marker 1 is a point of element 5
//   time,marker,x,y,z                      the header (or ...,x,y,z,wx,wy,wz)
//   0.00,0,0.1,0.2,0.3                     marker 0 at t = 0 s is at (0.1, 0.2, 0.3) m
//   0.04,1,0.1,0.2,0.3
//
// - Marker declarations come first; ids are integers >= 0, each declared once.
//   An element marker gives the element's local coordinates: for tet4 the
//   barycentric weights (b1, b2, b3) of nodes 1..3 (b0 = 1 - b1 - b2 - b3,
//   all in [0, 1]); for hex8 the reference coordinates (xi, eta, zeta) in
//   [-1, 1]^3 of the trilinear map (mesh.h's node convention).
// - The header names the sample columns: time (s, >= 0, measured from the
//   initial state of the simulation), marker (a declared id), position x, y,
//   z (m, each within +-kMaxMarkerCoordinate), and optionally per-axis
//   weights wx, wy, wz (in [0, kMaxMarkerWeight], default 1). A
//   calibration residual is weight * (simulated - captured), so a weight is
//   the inverse standard deviation of that coordinate (1/m) up to a common
//   factor, and 0 ignores it.
// - Samples may come in any order across markers, but each marker's times
//   must increase strictly. Frames need not align with simulation steps:
//   simulated positions are interpolated linearly in time (MarkerObservations).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "diffpd/mesh.h"
#include "diffpd/rollout.h"
#include "diffpd/types.h"

namespace diffpd {

// The largest marker coordinate magnitude accepted (m): 1000 km. Larger
// values are not the motion of a simulated body (and their squares, in a
// calibration's cost, overflow double precision near 1e154).
inline constexpr double kMaxMarkerCoordinate = 1e6;
// The largest per-axis weight accepted (1/m): the inverse of a picometre.
// With coordinates bounded as above, every weighted residual and its square
// stay far inside double precision.
inline constexpr double kMaxMarkerWeight = 1e12;

// A point fixed in the material: a mesh vertex, or a point of an element.
struct Marker {
  int id = 0;                 // >= 0, unique within a CapturedMotion
  int vertex = -1;            // >= 0: the marker is this vertex (and element is -1)
  int element = -1;           // >= 0: the marker is the point `local` of this element
  Vec3 local = Vec3::Zero();  // tet4 barycentric (b1, b2, b3) or hex8 (xi, eta, zeta)
  int line = 0;               // line of the declaration in its file (0: not from a file)
};

// Where marker `marker` was at time `time`.
struct MarkerSample {
  double time = 0;               // s, >= 0
  int marker = 0;                // a Marker::id
  Vec3 position = Vec3::Zero();  // m
  Vec3 weight = Vec3::Ones();    // per-axis residual weights, >= 0
  int line = 0;                  // line in its file (0: not from a file)
};

struct CapturedMotion {
  std::vector<Marker> markers;
  std::vector<MarkerSample> samples;  // in file order

  // The marker with this id, or nullptr.
  const Marker* FindMarker(int id) const;
  // Latest sample time (s); 0 without samples.
  double end_time() const;
  // Throws InvalidInputError naming the first problem, with the same
  // messages as ReadCapturedMotion (prefixed by `what` and the line when the
  // record came from a file, e.g. "plant.csv:12: ..."): a repeated or
  // negative marker id, a marker that is neither a vertex nor an element
  // point, a non-finite value, a negative time or weight, a coordinate
  // beyond kMaxMarkerCoordinate, an unknown marker id, a marker whose times
  // do not increase, no marker or no sample.
  void Validate(const std::string& what = "captured motion") const;
};

// Reads and validates a captured-motion file. Throws InvalidInputError,
// "<path>:<line>: <problem>" for a bad line, e.g.
//   "cannot open 'm.csv'", "cannot open 'm': it is a directory, not a file"
//   "m.csv:3: expected 'marker,<id>,vertex,<v>' or 'marker,<id>,element,<e>,<c0>,<c1>,<c2>', got 'marker,1,vertex'"
//   "m.csv:4: marker id 1 is declared twice (first on line 3)"
//   "m.csv:5: marker declarations must come before the header"
//   "m.csv:5: expected the header 'time,marker,x,y,z' or 'time,marker,x,y,z,wx,wy,wz', got '0,1,2,3,4'"
//   "m.csv:7: expected 5 fields (time,marker,x,y,z), got 4"
//   "m.csv:7: x is not a number: 'abc'"
//   "m.csv:7: marker is not an integer: '1.5'"
//   "m.csv:7: y = inf is not finite"
//   "m.csv:7: x = 1e+300 is invalid: must be within +-1000000 (m)"
//   "m.csv:7: time = -0.1 is invalid: must be >= 0 (s)"
//   "m.csv:7: wz = -1 is invalid: weights must be >= 0"
//   "m.csv:7: wx = 1e+300 is invalid: weights must be <= 1000000000000 (1/m)"
//   "m.csv:7: unknown marker id 9 (declared ids: 0, 1)"
//   "m.csv:9: time 0.1 of marker 0 is not after its previous sample at time 0.2 (line 8): times must increase strictly
//   per marker" "m.csv: no marker declared", "m.csv: no samples"
CapturedMotion ReadCapturedMotion(const std::string& path);

// Writes `motion` in the format above with 17 significant digits (exact
// round trip); weights are written only if some weight differs from 1.
// `comment` lines (split at '\n') are written first, each prefixed by "# ".
// Throws InvalidInputError "cannot write '<path>'".
void WriteCapturedMotion(const std::string& path, const CapturedMotion& motion, const std::string& comment = "");

// The nodes and weights of a marker on a mesh: its position is
// sum_a w_a x_{node_a} (weights sum to 1). Throws InvalidInputError:
//   "marker 3: vertex 99 is out of range (the mesh has 50 vertices)"
//   "marker 3: element 12 is out of range (the mesh has 10 elements)"
//   "marker 3: barycentric coordinates (0.5, 0.6, 0.1) are outside the tetrahedron (need b >= 0 and b1 + b2 + b3 <= 1)"
//   "marker 3: local coordinates (1.5, 0, 0) are outside the reference hexahedron [-1, 1]^3"
//   "marker 3: must be a vertex or an element point"
// (a tolerance of 1e-9 applies to the coordinate ranges).
std::vector<std::pair<int, double>> MarkerStencil(const Marker& marker, const Mesh& mesh);

// Synthetic captured motion: the positions of `markers` in a simulated
// trajectory (states[k] at time k h) at each of `times` (s, increasing, within
// [0, (states.size() - 1) h]), interpolated linearly in time as in
// MarkerObservations, plus independent Gaussian noise of standard deviation
// `noise` (m) on every coordinate, drawn from std::mt19937_64(seed) by the
// Box-Muller transform (portable: the same numbers on every platform).
// Samples are ordered by time, then by marker. Throws what MarkerStencil and
// MarkerObservations throw, and InvalidInputError for a negative noise.
CapturedMotion SampleMarkers(const Mesh& mesh, const std::vector<State>& states, double time_step,
                             const std::vector<Marker>& markers, const std::vector<double>& times, double noise = 0,
                             unsigned long long seed = 0);

// The linear map from a simulated trajectory x_0..x_K (step h) to the
// positions of the captured samples: sample s at time t, with
// t / h = k + alpha (0 <= alpha < 1), is observed at
//   (1 - alpha) X_k + alpha X_{k+1},  X_k = sum_a w_a x_k[node_a].
class MarkerObservations {
 public:
  // One term of a sample's stencil: weight * x_step[node].
  struct Term {
    int step;
    int node;
    double weight;
  };

  // Throws what CapturedMotion::Validate throws, what MarkerStencil throws
  // (prefixed by "line <l>: " for markers declared in a file),
  // InvalidInputError if h is not finite and > 0 ("time step = 0 is invalid:
  // must be finite and > 0 (s)") or num_steps < 0, and
  //   "line 12: time 2.5 s is after the end of the simulation (100 steps of 0.01 s = 1 s)"
  // ("sample <index>: ..." for a sample not from a file)
  // (times within 1e-9 h of the end are accepted).
  MarkerObservations(const CapturedMotion& motion, const Mesh& mesh, double time_step, int num_steps);

  // The most steps a captured motion may span (RequiredSteps): 10^5. A
  // calibration keeps its whole rollout for the backward pass, 2 x 3n
  // doubles per step: 10^5 steps of a 1000-node mesh are 4.8 GB.
  static constexpr int kMaxSteps = 100000;

  int num_samples() const { return static_cast<int>(terms_.size()); }
  int num_steps() const { return num_steps_; }
  const std::vector<Term>& terms(int sample) const { return terms_[sample]; }
  // Largest step any term of the sample uses.
  int last_step(int sample) const { return last_step_[sample]; }
  // Captured position and weights of sample s (copied from the motion).
  const Vec3& captured(int sample) const { return captured_[sample]; }
  const Vec3& weight(int sample) const { return weight_[sample]; }
  double time(int sample) const { return time_[sample]; }
  int marker(int sample) const { return marker_[sample]; }

  // Simulated position of sample s in a trajectory of at least
  // last_step(s) + 1 states, each with x of size 3n.
  Vec3 Simulated(int sample, const std::vector<State>& states) const;
  // Weighted residuals r = weight .* (simulated - captured), 3 per sample
  // (sample s axis d at 3 s + d).
  VectorXd Residuals(const std::vector<State>& states) const;

  // Number of simulation steps needed to reach the latest sample time (at
  // least 1). Throws InvalidInputError for a time step that is not finite
  // and > 0, and when it would exceed kMaxSteps:
  //   "line 9: time 10000 s needs 5e+06 steps of 0.002 s, more than the limit of 100000
  //   (MarkerObservations::kMaxSteps)" ("sample <index>: ..." for a sample not from a file).
  static int RequiredSteps(const CapturedMotion& motion, double time_step);

 private:
  int num_steps_ = 0;
  std::vector<std::vector<Term>> terms_;
  std::vector<int> last_step_;
  std::vector<Vec3> captured_;
  std::vector<Vec3> weight_;
  std::vector<double> time_;
  std::vector<int> marker_;
};

}  // namespace diffpd
