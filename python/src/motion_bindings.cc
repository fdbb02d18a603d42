// Captured marker motion and its observation map (diffpd/captured_motion.h).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/captured_motion.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {

void BindMotion(py::module_& m) {
  py::class_<Marker>(m, "Marker", "A tracked point: a vertex, or a point of an element.")
      .def(py::init<>())
      .def_readwrite("id", &Marker::id)
      .def_readwrite("vertex", &Marker::vertex)
      .def_readwrite("element", &Marker::element)
      .def_readwrite("local", &Marker::local)
      .def_readwrite("line", &Marker::line);
  py::class_<MarkerSample>(m, "MarkerSample", "One captured position of a marker at a time.")
      .def(py::init<>())
      .def_readwrite("time", &MarkerSample::time)
      .def_readwrite("marker", &MarkerSample::marker)
      .def_readwrite("position", &MarkerSample::position)
      .def_readwrite("weight", &MarkerSample::weight)
      .def_readwrite("line", &MarkerSample::line);
  py::class_<CapturedMotion>(m, "CapturedMotion", "Markers and their samples.")
      .def(py::init<>())
      .def_readwrite("markers", &CapturedMotion::markers)
      .def_readwrite("samples", &CapturedMotion::samples)
      .def("end_time", &CapturedMotion::end_time)
      .def("validate", &CapturedMotion::Validate, "what"_a = "captured motion");
  m.def("read_captured_motion", &ReadCapturedMotion, "path"_a);
  m.def("write_captured_motion", &WriteCapturedMotion, "path"_a, "motion"_a, "comment"_a = "");
  m.def("sample_markers", &SampleMarkers, "mesh"_a, "states"_a, "time_step"_a, "markers"_a, "times"_a, "noise"_a = 0.0,
        "seed"_a = 0ULL);

  py::class_<MarkerObservations>(m, "MarkerObservations",
                                 "The linear map from a trajectory to the captured samples' positions.")
      .def(py::init<const CapturedMotion&, const Mesh&, double, int>(), "motion"_a, "mesh"_a, "time_step"_a,
           "num_steps"_a)
      .def_static("required_steps", &MarkerObservations::RequiredSteps, "motion"_a, "time_step"_a)
      .def_property_readonly("num_samples", &MarkerObservations::num_samples)
      .def_property_readonly("num_steps", &MarkerObservations::num_steps)
      .def(
          "terms",
          [](const MarkerObservations& self, int sample) {
            py::list terms;
            for (const auto& t : self.terms(sample)) terms.append(py::make_tuple(t.step, t.node, t.weight));
            return terms;
          },
          "sample"_a, "The sample's stencil: (step, node, weight) tuples, position = sum weight x_step[node].")
      .def("captured", &MarkerObservations::captured, "sample"_a)
      .def("weight", &MarkerObservations::weight, "sample"_a)
      .def("time", &MarkerObservations::time, "sample"_a)
      .def("marker", &MarkerObservations::marker, "sample"_a)
      .def("residuals", &MarkerObservations::Residuals, "states"_a, "weight .* (simulated - captured), 3 per sample.");
}

}  // namespace diffpd::python
