// The simulator (diffpd/simulator.h). The long calls (simulate, step,
// backward, tangents, solve_quasi_static) release the GIL.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// K step inputs from optional K x 3n forces and K x (muscles) activations;
// a 1-D array is the same for every step.
std::vector<StepInput> MakeInputs(int steps, const py::object& external_force, const py::object& activation) {
  if (steps < 0) throw InvalidInputError("simulate: steps = " + std::to_string(steps) + " is invalid: must be >= 0");
  std::vector<StepInput> inputs(steps);
  auto fill = [&](const py::object& values, const char* name, VectorXd StepInput::*field) {
    if (values.is_none()) return;
    const py::array array = py::array::ensure(values);
    if (array.ndim() == 1) {
      const VectorXd row = values.cast<VectorXd>();
      for (StepInput& input : inputs) input.*field = row;
      return;
    }
    const RowMajorMatrix rows = values.cast<RowMajorMatrix>();
    if (rows.rows() != steps) {
      throw InvalidInputError(std::string("simulate: ") + name + " has " + std::to_string(rows.rows()) +
                              " rows, expected one per step (" + std::to_string(steps) + ")");
    }
    for (int k = 0; k < steps; ++k) inputs[k].*field = rows.row(k).transpose();
  };
  fill(external_force, "external_force", &StepInput::external_force);
  fill(activation, "activation", &StepInput::activation);
  return inputs;
}

}  // namespace

void BindSimulator(py::module_& m) {
  using release = py::call_guard<py::gil_scoped_release>;
  py::class_<Simulator>(m, "Simulator", "Steps a scene forward and differentiates rollouts (diffpd/simulator.h).")
      .def(py::init<const Scene&, const SolverOptions&>(), "scene"_a, "options"_a = SolverOptions{})
      .def_property_readonly("scene", &Simulator::scene, py::return_value_policy::reference_internal)
      .def_property_readonly("options", &Simulator::options)
      .def_property_readonly("num_dofs", &Simulator::num_dofs)
      .def("set_options", &Simulator::SetOptions, "options"_a)
      .def("set_material", &Simulator::SetMaterial, "material"_a)
      .def("set_region_material", &Simulator::SetRegionMaterial, "region"_a, "material"_a)
      .def("rest_state", &Simulator::RestState)
      .def("lumped_mass", &Simulator::LumpedMass, "Lumped mass per DoF (3n, kg).")
      .def("elastic_energy", &Simulator::ElasticEnergy, "x"_a, "Total elastic energy (J) at positions x (3n).")
      .def("explicit_stable_time_step", &Simulator::ExplicitStableTimeStep, "x"_a, "activation"_a = VectorXd(),
           "Semi-implicit Euler's stability limit (s) at positions x (3n): 2 / the highest natural frequency.")
      .def(
          "step",
          [](Simulator& self, const State& state, const StepInput& input) {
            StepReport report;
            State next = self.Step(state, input, &report);
            return py::make_tuple(std::move(next), report);
          },
          "state"_a, "input"_a = StepInput{}, "One step; returns (next state, StepReport).")
      .def("simulate", py::overload_cast<const State&, const std::vector<StepInput>&>(&Simulator::Simulate),
           "initial"_a, "inputs"_a, release(), "K = len(inputs) steps, recorded for backward().")
      .def(
          "simulate",
          [](Simulator& self, const State& initial, int steps, const py::object& external_force,
             const py::object& activation) {
            std::vector<StepInput> inputs = MakeInputs(steps, external_force, activation);
            py::gil_scoped_release unlocked;
            return self.Simulate(initial, inputs);
          },
          "initial"_a, "steps"_a, py::kw_only(), "external_force"_a = py::none(), "activation"_a = py::none(),
          "`steps` steps; external_force (steps x 3n or 3n) and activation (steps x muscles or muscles) optional.")
      .def("simulate", py::overload_cast<const State&, const Controller&, int>(&Simulator::Simulate), "initial"_a,
           "controller"_a, "steps"_a, release(), "Closed loop: the controller acts at every step.")
      .def("backward", py::overload_cast<const Rollout&, const LossGradient&>(&Simulator::Backward), "rollout"_a,
           "loss"_a, release(), "Reverse mode: gradients of a loss given dL/dx_k and dL/dv_k.")
      .def("backward", py::overload_cast<const Rollout&, const LossGradient&, const Controller&>(&Simulator::Backward),
           "rollout"_a, "loss"_a, "controller"_a, release(), "Closed loop: also dL/dtheta of the controller.")
      .def("tangents", py::overload_cast<const Rollout&, const std::vector<InputDirection>&>(&Simulator::Tangents),
           "rollout"_a, "directions"_a, release(), "Forward mode: dx_k, dv_k along each direction.")
      .def(
          "solve_quasi_static",
          [](Simulator& self, const VectorXd& x0, const StepInput& input) {
            StepReport report;
            VectorXd x;
            {
              py::gil_scoped_release unlocked;
              x = self.SolveQuasiStatic(x0, input, &report);
            }
            return py::make_tuple(x, report);
          },
          "initial_positions"_a, "input"_a = StepInput{}, "Equilibrium positions (3n) and the StepReport.")
      .def_property_readonly("num_pd_factorizations", &Simulator::num_pd_factorizations)
      .def_property_readonly("pd_factorization_seconds", &Simulator::pd_factorization_seconds);
}

}  // namespace diffpd::python
