// The project's registered problems (problems/problem_registry.h) as the
// submodule diffpd.problems: their scenes, initial states and inputs, and the
// extras the Python examples use (a calibration problem's data and markers,
// a swimmer's scene, controller and loss).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/error.h"
#include "problem_registry.h"
#if DIFFPD_PYTHON_WITH_CALIBRATION
#include "calibration/calibrate_problem.h"
#endif
#if DIFFPD_PYTHON_WITH_CONTROL
#include "control/swimmer_control.h"
#endif

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {
namespace {

using problems::Problem;

template <class Derived>
const Derived& As(const Problem& problem, const char* kind) {
  const auto* derived = dynamic_cast<const Derived*>(&problem);
  if (!derived) throw InvalidInputError("problem '" + problem.name() + "' is not a " + kind + " problem");
  return *derived;
}

}  // namespace

void BindProblems(py::module_& parent) {
  py::module_ m = parent.def_submodule("problems", "The registered problems (`diffpd list`).");
  py::class_<Problem> problem(m, "Problem", "A concrete scene with its default run settings.");
  problem.def_property_readonly("name", &Problem::name)
      .def_property_readonly("description", &Problem::description)
      .def("make_scene", &Problem::MakeScene)
      .def("initial_state", &Problem::InitialState, "simulator"_a)
      .def_property_readonly("default_steps", &Problem::default_steps)
      .def_property_readonly("default_time_step", &Problem::default_time_step)
      .def("inputs", &Problem::Inputs, "simulator"_a, "steps"_a);
  m.def(
      "names",
      [] {
        std::vector<std::string> names;
        for (const auto& p : problems::AllProblems()) names.push_back(p->name());
        return names;
      },
      "Names of the registered problems, as `diffpd list` prints them.");
  m.def("make", &problems::MakeProblem, "name"_a, "The problem called `name`.");

#if DIFFPD_PYTHON_WITH_CALIBRATION
  using problems::CalibrationProblem;
  problem
      .def(
          "data_path", [](const Problem& p) { return As<CalibrationProblem>(p, "calibration").DefaultDataPath(); },
          "Calibration: the shipped captured motion (data/).")
      .def(
          "truth", [](const Problem& p) { return As<CalibrationProblem>(p, "calibration").truth(); },
          "Calibration: the material the motion was made with.")
      .def(
          "initial_guess", [](const Problem& p) { return As<CalibrationProblem>(p, "calibration").initial_guess(); },
          "Calibration: where every fit starts.")
      .def(
          "fit_options",
          [](const Problem& p, Method method) { return As<CalibrationProblem>(p, "calibration").FitOptions(method); },
          "method"_a, "Calibration: the simulator settings of a fit.")
      .def(
          "max_fit_iterations",
          [](const Problem& p) { return As<CalibrationProblem>(p, "calibration").max_iterations(); },
          "Calibration: the C++ fit's iteration limit.");
#endif

#if DIFFPD_PYTHON_WITH_CONTROL
  using problems::SwimLoss;
  using problems::Swimmer;
  py::class_<SwimLoss>(m, "SwimLoss", "L = sum_k -d . vbar_k + side_weight |vbar_k - (d . vbar_k) d|^2.")
      .def_readonly("nodes", &SwimLoss::nodes)
      .def_readonly("direction", &SwimLoss::direction)
      .def_readonly("side_weight", &SwimLoss::side_weight)
      .def(
          "evaluate", [](const SwimLoss& self, const Rollout& rollout) { return self.Evaluate(rollout, nullptr); },
          "rollout"_a);
  py::class_<Swimmer>(m, "Swimmer", "A swimmer: scene, muscle strips, drives, observation, loss, length.")
      .def_readonly("scene", &Swimmer::scene)
      .def_readonly("strips", &Swimmer::strips)
      .def_readonly("drives", &Swimmer::drives)
      .def_readonly("observation", &Swimmer::observation)
      .def_readonly("hidden_widths", &Swimmer::hidden_widths)
      .def_readonly("channels", &Swimmer::channels)
      .def_readonly("loss", &Swimmer::loss)
      .def_readonly("steps", &Swimmer::steps)
      .def_readonly("time_step", &Swimmer::time_step);
  m.def("make_swimmer_controller", &problems::MakeSwimmerController, "swimmer"_a, "seed"_a,
        "The swimmer's network controller with the C++ training's initialisation.");
  problem
      .def(
          "make_swimmer",
          [](const Problem& p, bool small) { return As<problems::SwimmerControl>(p, "swimmer").MakeSwimmer(small); },
          "small"_a = false)
      .def(
          "swimmer_options",
          [](const Problem& p, bool small) { return As<problems::SwimmerControl>(p, "swimmer").BaseOptions(small); },
          "small"_a = false, "Swimmer: the step solver settings of its training.");
#endif
}

}  // namespace diffpd::python
