// Closed-loop control (diffpd/controller.h) and the library's controller:
// an MLP (mlp.h) driving muscle strips through a delay line
// (strip_network_controller.h, muscle_strip.h).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/controller.h"
#include "diffpd/mlp.h"
#include "diffpd/muscle_strip.h"
#include "diffpd/strip_network_controller.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {

void BindController(py::module_& m) {
  py::class_<ControlAction> action(m, "ControlAction", "One step's action: activations and external force.");
  action.def(py::init<>());
  EigenMember(action, "activation", &ControlAction::activation, "one per muscle, or empty; a view");
  EigenMember(action, "external_force", &ControlAction::external_force, "3n (N), or empty; a view");

  py::class_<Controller>(m, "Controller", "A differentiable policy (diffpd/controller.h); see StripNetworkController.")
      .def_property_readonly("num_parameters", &Controller::num_parameters)
      .def_property_readonly("parameters", &Controller::parameters)
      .def("set_parameters", &Controller::SetParameters, "parameters"_a)
      .def_property_readonly("memory_size", &Controller::memory_size)
      .def("initial_memory", &Controller::InitialMemory)
      .def(
          "act",
          [](const Controller& self, int step, const State& state, const VectorXd& memory) {
            ControlAction result;
            VectorXd next_memory;
            self.Act(step, state, memory, &result, &next_memory);
            return py::make_tuple(result, next_memory);
          },
          "step"_a, "state"_a, "memory"_a, "(action, next_memory) at step k.")
      .def("clone", &Controller::Clone);

  py::enum_<MlpNonlinearity>(m, "MlpNonlinearity")
      .value("TANH", MlpNonlinearity::kTanh)
      .value("IDENTITY", MlpNonlinearity::kIdentity);
  py::class_<MlpTape>(m, "MlpTape", "The values of one forward pass that the backward pass needs: z_0..z_L.")
      .def(py::init<>())
      .def_readonly("z", &MlpTape::z);
  py::class_<Mlp>(m, "Mlp", "A fully connected network (diffpd/mlp.h).")
      .def(py::init<std::vector<int>, MlpNonlinearity, MlpNonlinearity>(), "widths"_a,
           "hidden"_a = MlpNonlinearity::kTanh, "output"_a = MlpNonlinearity::kIdentity)
      .def_property_readonly("widths", &Mlp::widths)
      .def_property_readonly("num_layers", &Mlp::num_layers)
      .def_property_readonly("num_inputs", &Mlp::num_inputs)
      .def_property_readonly("num_outputs", &Mlp::num_outputs)
      .def_property_readonly("num_parameters", &Mlp::num_parameters)
      .def_property_readonly("parameters", &Mlp::parameters, py::return_value_policy::reference_internal,
                             "theta (read-only view)")
      .def("set_parameters", &Mlp::SetParameters, "parameters"_a)
      .def("initialize_orthogonal", &Mlp::InitializeOrthogonal, "seed"_a, "gain"_a)
      .def("evaluate", &Mlp::Evaluate, "input"_a)
      .def(
          "forward",
          [](const Mlp& self, const VectorXd& input) {
            MlpTape tape;
            VectorXd output = self.Forward(input, &tape);
            return py::make_tuple(output, tape);
          },
          "input"_a, "(output, tape): the output, recording the tape for backward().")
      .def(
          "backward",
          [](const Mlp& self, const MlpTape& tape, const VectorXd& g_output) {
            VectorXd g_input;
            VectorXd g_parameters = VectorXd::Zero(self.num_parameters());
            self.Backward(tape, g_output, &g_input, &g_parameters);
            return py::make_tuple(g_input, g_parameters);
          },
          "tape"_a, "g_output"_a, "(dL/dinput, dL/dtheta) at the tape's point, given dL/doutput.");

  py::class_<MuscleDelayLine>(m, "MuscleDelayLine", "Strips' activations delayed root to tip (muscle_strip.h).")
      .def(py::init<std::vector<std::vector<int>>, int>(), "strip_muscles"_a, "num_muscles"_a)
      .def_property_readonly("num_strips", &MuscleDelayLine::num_strips)
      .def_property_readonly("num_muscles", &MuscleDelayLine::num_muscles)
      .def_property_readonly("memory_size", &MuscleDelayLine::memory_size);
  py::class_<NodeObservation>(m, "NodeObservation", "What the network sees: nodes relative to a reference node.")
      .def(py::init<>())
      .def_readwrite("reference_node", &NodeObservation::reference_node)
      .def_readwrite("nodes", &NodeObservation::nodes)
      .def_property_readonly("size", &NodeObservation::size);
  py::class_<StripDrive>(m, "StripDrive", "Which network output drives a strip, with which sign.")
      .def(py::init([](int channel, int sign) {
             return StripDrive{channel, sign};
           }),
           "channel"_a = 0, "sign"_a = 1)
      .def_readwrite("channel", &StripDrive::channel)
      .def_readwrite("sign", &StripDrive::sign);
  py::class_<StripNetworkController, Controller>(m, "StripNetworkController",
                                                 "An MLP driving muscle strips (strip_network_controller.h).")
      .def(py::init<Mlp, NodeObservation, MuscleDelayLine, std::vector<StripDrive>, int>(), "network"_a,
           "observation"_a, "delay_line"_a, "drives"_a, "num_nodes"_a)
      .def_property_readonly("network", &StripNetworkController::network, py::return_value_policy::reference_internal)
      .def_property_readonly("observation", &StripNetworkController::observation)
      .def("observe", &StripNetworkController::Observe, "state"_a);
}

}  // namespace diffpd::python
