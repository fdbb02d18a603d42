// Captured-motion CSV files, marker stencils and the time interpolation of
// simulated trajectories at capture times.
#include "diffpd/captured_motion.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "diffpd/csv_fields.h"
#include "diffpd/error.h"
#include "diffpd/input_file.h"

namespace diffpd {
namespace {

bool ParseInteger(const std::string& s, long* value) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *value = std::strtol(s.c_str(), &end, 10);
  return end == s.c_str() + s.size() && errno == 0;
}

// 15 significant digits: a value just beyond a limit prints unlike the limit.
std::string Format(double v) {
  std::ostringstream out;
  out.precision(15);
  out << v;
  return out.str();
}

// Prefix "<what>:<line>: " or "<what>: " of a message about a record.
std::string Where(const std::string& what, int line) {
  return line > 0 ? what + ":" + std::to_string(line) + ": " : what + ": ";
}

// Checks of one marker declaration that do not need the mesh.
void CheckMarker(const Marker& m, const std::string& what) {
  const std::string at = Where(what, m.line);
  if (m.id < 0)
    throw InvalidInputError(at + "marker id " + std::to_string(m.id) + " is invalid: must be an integer >= 0");
  const bool is_vertex = m.vertex >= 0 && m.element < 0;
  const bool is_point = m.element >= 0 && m.vertex < 0;
  if (!is_vertex && !is_point)
    throw InvalidInputError(at + "marker " + std::to_string(m.id) + ": must be a vertex or an element point");
  if (is_point && !m.local.allFinite())
    throw InvalidInputError(at + "marker " + std::to_string(m.id) + ": local coordinates are not finite");
}

// Checks of one sample given the already accepted ones; `last` maps marker id
// to (time, line) of its latest sample.
void CheckSample(const MarkerSample& s, const std::map<int, const Marker*>& ids,
                 std::map<int, std::pair<double, int>>* last, const std::string& what) {
  const std::string at = Where(what, s.line);
  const char* axes[3] = {"x", "y", "z"};
  const char* weights[3] = {"wx", "wy", "wz"};
  if (!std::isfinite(s.time)) throw InvalidInputError(at + "time = " + Format(s.time) + " is not finite");
  if (s.time < 0) throw InvalidInputError(at + "time = " + Format(s.time) + " is invalid: must be >= 0 (s)");
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(s.position(d)))
      throw InvalidInputError(at + axes[d] + " = " + Format(s.position(d)) + " is not finite");
    if (std::abs(s.position(d)) > kMaxMarkerCoordinate)
      throw InvalidInputError(at + axes[d] + " = " + Format(s.position(d)) + " is invalid: must be within +-" +
                              Format(kMaxMarkerCoordinate) + " (m)");
  }
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(s.weight(d)))
      throw InvalidInputError(at + weights[d] + " = " + Format(s.weight(d)) + " is not finite");
    if (s.weight(d) < 0)
      throw InvalidInputError(at + weights[d] + " = " + Format(s.weight(d)) + " is invalid: weights must be >= 0");
    if (s.weight(d) > kMaxMarkerWeight)
      throw InvalidInputError(at + weights[d] + " = " + Format(s.weight(d)) +
                              " is invalid: weights must be <= " + Format(kMaxMarkerWeight) + " (1/m)");
  }
  if (!ids.count(s.marker)) {
    std::string list;
    for (const auto& kv : ids) list += (list.empty() ? "" : ", ") + std::to_string(kv.first);
    throw InvalidInputError(at + "unknown marker id " + std::to_string(s.marker) + " (declared ids: " + list + ")");
  }
  auto it = last->find(s.marker);
  if (it != last->end() && !(s.time > it->second.first)) {
    std::string prev = "at time " + Format(it->second.first);
    if (it->second.second > 0) prev += " (line " + std::to_string(it->second.second) + ")";
    throw InvalidInputError(at + "time " + Format(s.time) + " of marker " + std::to_string(s.marker) +
                            " is not after its previous sample " + prev + ": times must increase strictly per marker");
  }
  (*last)[s.marker] = {s.time, s.line};
}

std::map<int, const Marker*> MarkerIds(const std::vector<Marker>& markers, const std::string& what) {
  std::map<int, const Marker*> ids;
  for (const Marker& m : markers) {
    CheckMarker(m, what);
    auto [it, inserted] = ids.emplace(m.id, &m);
    if (!inserted) {
      std::string first = it->second->line > 0 ? " (first on line " + std::to_string(it->second->line) + ")" : "";
      throw InvalidInputError(Where(what, m.line) + "marker id " + std::to_string(m.id) + " is declared twice" + first);
    }
  }
  return ids;
}

void CheckTimeStep(double time_step) {
  if (!std::isfinite(time_step) || time_step <= 0)
    throw InvalidInputError("time step = " + Format(time_step) + " is invalid: must be finite and > 0 (s)");
}

// "line <l>: " for a sample from a file, else "sample <index>: ".
std::string SampleName(const MarkerSample& s, int index) {
  return s.line > 0 ? "line " + std::to_string(s.line) + ": " : "sample " + std::to_string(index) + ": ";
}

}  // namespace

const Marker* CapturedMotion::FindMarker(int id) const {
  for (const Marker& m : markers)
    if (m.id == id) return &m;
  return nullptr;
}

double CapturedMotion::end_time() const {
  double t = 0;
  for (const MarkerSample& s : samples) t = std::max(t, s.time);
  return t;
}

void CapturedMotion::Validate(const std::string& what) const {
  const std::map<int, const Marker*> ids = MarkerIds(markers, what);
  std::map<int, std::pair<double, int>> last;
  for (const MarkerSample& s : samples) CheckSample(s, ids, &last, what);
  if (markers.empty()) throw InvalidInputError(what + ": no marker declared");
  if (samples.empty()) throw InvalidInputError(what + ": no samples");
}

CapturedMotion ReadCapturedMotion(const std::string& path) {
  std::ifstream in = OpenInputFile(path);
  CapturedMotion motion;
  std::map<int, const Marker*> ids;
  std::map<int, std::pair<double, int>> last;
  int num_fields = 0;  // 0 until the header was read
  std::string raw;
  int line_number = 0;
  auto fail = [&](const std::string& message) {
    throw InvalidInputError(path + ":" + std::to_string(line_number) + ": " + message);
  };
  while (std::getline(in, raw)) {
    ++line_number;
    const std::string line = TrimCsvField(raw);
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> f = SplitCsvLine(line);
    if (f[0] == "marker") {
      if (num_fields) fail("marker declarations must come before the header");
      Marker m;
      m.line = line_number;
      long id = 0, index = 0;
      const bool vertex = f.size() == 4 && f[2] == "vertex";
      const bool element = f.size() == 7 && f[2] == "element";
      bool ok = (vertex || element) && ParseInteger(f[1], &id) && ParseInteger(f[3], &index);
      for (int c = 0; ok && element && c < 3; ++c) ok = ParseCsvNumber(f[4 + c], &m.local(c));
      if (!ok)
        fail("expected 'marker,<id>,vertex,<v>' or 'marker,<id>,element,<e>,<c0>,<c1>,<c2>', got '" + line + "'");
      m.id = static_cast<int>(id);
      if (id < 0 || id != m.id) fail("marker id " + f[1] + " is invalid: must be an integer >= 0");
      if (index < 0 || index != static_cast<int>(index))
        fail(std::string(vertex ? "vertex" : "element") + " index " + f[3] + " is invalid: must be an integer >= 0");
      (vertex ? m.vertex : m.element) = static_cast<int>(index);
      motion.markers.push_back(m);
      continue;
    }
    if (!num_fields) {
      static const std::vector<std::string> kHeader = {"time", "marker", "x", "y", "z", "wx", "wy", "wz"};
      const bool short_header = f.size() == 5 && std::equal(f.begin(), f.end(), kHeader.begin());
      const bool long_header = f.size() == 8 && std::equal(f.begin(), f.end(), kHeader.begin());
      if (!short_header && !long_header)
        fail("expected the header 'time,marker,x,y,z' or 'time,marker,x,y,z,wx,wy,wz', got '" + line + "'");
      num_fields = static_cast<int>(f.size());
      ids = MarkerIds(motion.markers, path);
      continue;
    }
    if (static_cast<int>(f.size()) != num_fields)
      fail("expected " + std::to_string(num_fields) + " fields (" +
           (num_fields == 5 ? "time,marker,x,y,z" : "time,marker,x,y,z,wx,wy,wz") + "), got " +
           std::to_string(f.size()));
    MarkerSample s;
    s.line = line_number;
    static const char* kNames[8] = {"time", "marker", "x", "y", "z", "wx", "wy", "wz"};
    double values[8];
    for (int c = 0; c < num_fields; ++c) {
      if (c == 1) continue;
      if (!ParseCsvNumber(f[c], &values[c])) fail(std::string(kNames[c]) + " is not a number: '" + f[c] + "'");
    }
    long id = 0;
    if (!ParseInteger(f[1], &id) || id != static_cast<int>(id)) fail("marker is not an integer: '" + f[1] + "'");
    s.time = values[0];
    s.marker = static_cast<int>(id);
    s.position = Vec3(values[2], values[3], values[4]);
    if (num_fields == 8) s.weight = Vec3(values[5], values[6], values[7]);
    CheckSample(s, ids, &last, path);
    motion.samples.push_back(s);
  }
  if (motion.markers.empty()) throw InvalidInputError(path + ": no marker declared");
  if (motion.samples.empty()) throw InvalidInputError(path + ": no samples");
  return motion;
}

void WriteCapturedMotion(const std::string& path, const CapturedMotion& motion, const std::string& comment) {
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
  if (!comment.empty()) {
    std::istringstream lines(comment);
    std::string line;
    while (std::getline(lines, line)) out << "# " << line << "\n";
  }
  char buffer[256];
  for (const Marker& m : motion.markers) {
    if (m.vertex >= 0) {
      out << "marker," << m.id << ",vertex," << m.vertex << "\n";
    } else {
      std::snprintf(buffer, sizeof buffer, "marker,%d,element,%d,%.17g,%.17g,%.17g\n", m.id, m.element, m.local(0),
                    m.local(1), m.local(2));
      out << buffer;
    }
  }
  bool weights = false;
  for (const MarkerSample& s : motion.samples) weights = weights || s.weight != Vec3::Ones();
  out << (weights ? "time,marker,x,y,z,wx,wy,wz\n" : "time,marker,x,y,z\n");
  for (const MarkerSample& s : motion.samples) {
    std::snprintf(buffer, sizeof buffer, "%.17g,%d,%.17g,%.17g,%.17g", s.time, s.marker, s.position(0), s.position(1),
                  s.position(2));
    out << buffer;
    if (weights) {
      std::snprintf(buffer, sizeof buffer, ",%.17g,%.17g,%.17g", s.weight(0), s.weight(1), s.weight(2));
      out << buffer;
    }
    out << "\n";
  }
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
}

std::vector<std::pair<int, double>> MarkerStencil(const Marker& marker, const Mesh& mesh) {
  const std::string name = "marker " + std::to_string(marker.id) + ": ";
  if (marker.vertex >= 0 && marker.element < 0) {
    if (marker.vertex >= mesh.num_vertices())
      throw InvalidInputError(name + "vertex " + std::to_string(marker.vertex) + " is out of range (the mesh has " +
                              std::to_string(mesh.num_vertices()) + " vertices)");
    return {{marker.vertex, 1.0}};
  }
  if (marker.element < 0 || marker.vertex >= 0 || !marker.local.allFinite())
    throw InvalidInputError(name + "must be a vertex or an element point");
  if (marker.element >= mesh.num_elements())
    throw InvalidInputError(name + "element " + std::to_string(marker.element) + " is out of range (the mesh has " +
                            std::to_string(mesh.num_elements()) + " elements)");
  const Vec3& c = marker.local;
  const std::string coords = "(" + Format(c(0)) + ", " + Format(c(1)) + ", " + Format(c(2)) + ")";
  const double tol = 1e-9;
  std::vector<std::pair<int, double>> stencil;
  if (mesh.type == ElementType::kTet4) {
    const double b0 = 1 - c.sum();
    if (c.minCoeff() < -tol || b0 < -tol)
      throw InvalidInputError(name + "barycentric coordinates " + coords +
                              " are outside the tetrahedron (need b >= 0 and b1 + b2 + b3 <= 1)");
    stencil.emplace_back(mesh.elements(0, marker.element), b0);
    for (int a = 0; a < 3; ++a) stencil.emplace_back(mesh.elements(a + 1, marker.element), c(a));
  } else {
    if (c.cwiseAbs().maxCoeff() > 1 + tol)
      throw InvalidInputError(name + "local coordinates " + coords + " are outside the reference hexahedron [-1, 1]^3");
    for (int a = 0; a < 8; ++a) {
      const Vec3 corner(2 * ((a >> 2) & 1) - 1, 2 * ((a >> 1) & 1) - 1, 2 * (a & 1) - 1);
      const double w = (1 + c(0) * corner(0)) * (1 + c(1) * corner(1)) * (1 + c(2) * corner(2)) / 8;
      stencil.emplace_back(mesh.elements(a, marker.element), w);
    }
  }
  return stencil;
}

int MarkerObservations::RequiredSteps(const CapturedMotion& motion, double time_step) {
  CheckTimeStep(time_step);
  const MarkerSample* last = nullptr;
  for (const MarkerSample& s : motion.samples)
    if (!last || s.time > last->time) last = &s;
  if (!last) return 1;
  const double steps = std::ceil(last->time / time_step - 1e-9);
  if (!(steps <= kMaxSteps)) {  // also NaN
    std::ostringstream msg;
    msg << SampleName(*last, static_cast<int>(last - motion.samples.data())) << "time " << last->time << " s needs "
        << steps << " steps of " << time_step << " s, more than the limit of " << kMaxSteps
        << " (MarkerObservations::kMaxSteps)";
    throw InvalidInputError(msg.str());
  }
  return std::max(1, static_cast<int>(steps));
}

MarkerObservations::MarkerObservations(const CapturedMotion& motion, const Mesh& mesh, double time_step, int num_steps)
    : num_steps_(num_steps) {
  CheckTimeStep(time_step);
  if (num_steps < 0)
    throw InvalidInputError("number of steps = " + std::to_string(num_steps) + " is invalid: must be >= 0");
  motion.Validate();
  std::map<int, std::vector<std::pair<int, double>>> stencils;
  for (const Marker& m : motion.markers) {
    try {
      stencils[m.id] = MarkerStencil(m, mesh);
    } catch (const InvalidInputError& e) {
      if (m.line > 0) throw InvalidInputError("line " + std::to_string(m.line) + ": " + e.what());
      throw;
    }
  }
  for (const MarkerSample& s : motion.samples) {
    auto it = stencils.find(s.marker);
    DIFFPD_CHECK(it != stencils.end(), "validated motion has an unknown marker id " << s.marker);
    // Compared as doubles first: tau may exceed any int.
    const double tau = s.time / time_step;
    if (tau > num_steps + 1e-9) {
      std::ostringstream msg;
      msg << SampleName(s, static_cast<int>(terms_.size())) << "time " << s.time
          << " s is after the end of the simulation (" << num_steps << " steps of " << time_step
          << " s = " << num_steps * time_step << " s)";
      throw InvalidInputError(msg.str());
    }
    const int k = std::min(num_steps, static_cast<int>(std::floor(tau + 1e-9)));
    double alpha = std::max(0.0, tau - k);
    if (alpha < 1e-9 || k == num_steps) alpha = 0;
    std::vector<Term> terms;
    for (const auto& [node, w] : it->second) {
      terms.push_back({k, node, (1 - alpha) * w});
      if (alpha > 0) terms.push_back({k + 1, node, alpha * w});
    }
    terms_.push_back(std::move(terms));
    last_step_.push_back(alpha > 0 ? k + 1 : k);
    captured_.push_back(s.position);
    weight_.push_back(s.weight);
    time_.push_back(s.time);
    marker_.push_back(s.marker);
  }
}

Vec3 MarkerObservations::Simulated(int sample, const std::vector<State>& states) const {
  Vec3 p = Vec3::Zero();
  for (const Term& t : terms_[sample]) p += t.weight * states[t.step].x.segment<3>(3 * t.node);
  return p;
}

VectorXd MarkerObservations::Residuals(const std::vector<State>& states) const {
  VectorXd r(3 * num_samples());
  for (int s = 0; s < num_samples(); ++s)
    r.segment<3>(3 * s) = weight_[s].cwiseProduct(Simulated(s, states) - captured_[s]);
  return r;
}

CapturedMotion SampleMarkers(const Mesh& mesh, const std::vector<State>& states, double time_step,
                             const std::vector<Marker>& markers, const std::vector<double>& times, double noise,
                             unsigned long long seed) {
  if (!std::isfinite(noise) || noise < 0)
    throw InvalidInputError("noise = " + Format(noise) + " is invalid: must be finite and >= 0 (m)");
  if (states.empty()) throw InvalidInputError("SampleMarkers: no states");
  CapturedMotion motion;
  motion.markers = markers;
  for (double t : times)
    for (const Marker& m : markers) motion.samples.push_back(MarkerSample{t, m.id, Vec3::Zero(), Vec3::Ones(), 0});
  const MarkerObservations obs(motion, mesh, time_step, static_cast<int>(states.size()) - 1);
  std::mt19937_64 rng(seed);
  // Uniform in (0, 1] from the top 53 bits, then Box-Muller.
  auto uniform = [&rng]() { return (static_cast<double>(rng() >> 11) + 1.0) * 0x1.0p-53; };
  const double two_pi = 6.283185307179586476925286766559;
  for (int s = 0; s < obs.num_samples(); ++s) {
    Vec3 p = obs.Simulated(s, states);
    if (noise > 0)
      for (int d = 0; d < 3; ++d) p(d) += noise * std::sqrt(-2 * std::log(uniform())) * std::cos(two_pi * uniform());
    motion.samples[s].position = p;
  }
  return motion;
}

}  // namespace diffpd
