// States, step inputs, reports, rollouts, loss gradients, rollout gradients
// and tangents (diffpd/rollout.h, tangent_rollout.h). Vectors held by these
// structs (State.x, RolloutGradient.x0, ...) are views of their memory;
// per-step lists are copied into Python lists, and the *_array() helpers
// stack them into one (K x 3n) array.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/error.h"
#include "diffpd/rollout.h"
#include "diffpd/tangent_rollout.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {
namespace {

// Rows = the vectors (all of one length; empty ones are zero rows of the
// common length), as one C-contiguous (len x n) array.
py::array_t<double> Stack(const std::vector<VectorXd>& rows) {
  Eigen::Index n = 0;
  for (const VectorXd& row : rows) n = std::max(n, row.size());
  py::array_t<double> result({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(n)});
  auto out = result.mutable_unchecked<2>();
  for (size_t k = 0; k < rows.size(); ++k) {
    for (Eigen::Index i = 0; i < n; ++i) out(k, i) = rows[k].size() ? rows[k][i] : 0.0;
  }
  return result;
}

// The rows of a (len x n) array (None: `len` empty vectors).
std::vector<VectorXd> Unstack(const py::object& array, size_t len) {
  if (array.is_none()) return std::vector<VectorXd>(len);
  const auto a = array.cast<Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>>();
  std::vector<VectorXd> rows(a.rows());
  for (Eigen::Index k = 0; k < a.rows(); ++k) rows[k] = a.row(k).transpose();
  return rows;
}

}  // namespace

void BindRollout(py::module_& m) {
  py::class_<State> state(m, "State", "Positions x and velocities v, each 3n (node i axis d at 3 i + d).");
  state.def(py::init<>())
      .def(py::init([](VectorXd x, VectorXd v) {
             return State{std::move(x), std::move(v)};
           }),
           "x"_a, "v"_a);
  EigenMember(state, "x", &State::x, "positions (m), 3n; a view of the state's memory");
  EigenMember(state, "v", &State::v, "velocities (m/s), 3n; a view of the state's memory");
  state.def("copy", [](const State& s) { return State(s); });

  py::class_<StepInput> input(m, "StepInput", "What drives one step: external force (3n, N) and muscle activations.");
  input.def(py::init<>())
      .def(py::init([](VectorXd external_force, VectorXd activation) {
             return StepInput{std::move(external_force), std::move(activation)};
           }),
           "external_force"_a = VectorXd(), "activation"_a = VectorXd());
  EigenMember(input, "external_force", &StepInput::external_force, "3n (N), or empty for none; a view");
  EigenMember(input, "activation", &StepInput::activation, "one per muscle, or empty (at rest); a view");
  input.def_property(
      "wetted_quads",
      [](const StepInput& in) { return std::vector<bool>(in.wetted_quads.begin(), in.wetted_quads.end()); },
      [](StepInput& in, const std::vector<bool>& wetted) { in.wetted_quads.assign(wetted.begin(), wetted.end()); },
      "Scene.quad_hydrodynamics only: per face, held wet (True) or dry (False) during the step; empty (the "
      "default): each face's state decides (see wetted_quads()); a copy");

  py::class_<StepReport> step_report(m, "StepReport", "Outcome of one step.");
  step_report.def(py::init<>())
      .def_readonly("iterations", &StepReport::iterations)
      .def_readonly("line_search_steps", &StepReport::line_search_steps)
      .def_readonly("initial_residual", &StepReport::initial_residual)
      .def_readonly("final_residual", &StepReport::final_residual)
      .def_readonly("seconds", &StepReport::seconds)
      .def_readonly("energy_restarts", &StepReport::energy_restarts)
      .def_readonly("rounding_floor_stop", &StepReport::rounding_floor_stop)
      .def_readonly("newton_fallback", &StepReport::newton_fallback)
      .def_readonly("contact_nodes", &StepReport::contact_nodes)
      .def_readonly("contact_forces", &StepReport::contact_forces)
      .def_readonly("active_set_passes", &StepReport::active_set_passes);

  py::class_<Rollout>(m, "Rollout", "A recorded trajectory: states[0..K], inputs[0..K-1] and how it was made.")
      .def(py::init<>())
      .def_property_readonly(
          "states",
          [](py::object self) {
            Rollout& r = self.cast<Rollout&>();
            py::list states;
            for (State& s : r.states) states.append(py::cast(&s, py::return_value_policy::reference_internal, self));
            return states;
          },
          "The states as views into the rollout (valid while it lives).")
      .def_readwrite("inputs", &Rollout::inputs)
      .def_readonly("reports", &Rollout::reports)
      .def_readwrite("material", &Rollout::material)
      .def_readwrite("region_materials", &Rollout::region_materials)
      .def_readwrite("options", &Rollout::options)
      .def_readonly("controller_memory", &Rollout::controller_memory)
      .def_readonly("controller_parameters", &Rollout::controller_parameters)
      .def_property_readonly("num_steps", &Rollout::num_steps)
      .def_property_readonly("closed_loop", &Rollout::closed_loop)
      .def("forward_seconds", &Rollout::forward_seconds)
      .def("truncated", &Rollout::Truncated, "num_steps"_a)
      .def(
          "positions",
          [](const Rollout& r) {
            std::vector<VectorXd> rows;
            for (const State& s : r.states) rows.push_back(s.x);
            return Stack(rows);
          },
          "x_0..x_K as one (K+1) x 3n array (a copy).")
      .def(
          "velocities",
          [](const Rollout& r) {
            std::vector<VectorXd> rows;
            for (const State& s : r.states) rows.push_back(s.v);
            return Stack(rows);
          },
          "v_0..v_K as one (K+1) x 3n array (a copy).");

  py::class_<LossGradient>(m, "LossGradient", "dL/dx_k and dL/dv_k, k = 0..K (each 3n, or empty for zero).")
      .def(py::init<int>(), "num_steps"_a = 0)
      .def(py::init([](const py::object& dx, const py::object& dv) {
             const size_t len = !dx.is_none() ? py::len(dx) : (!dv.is_none() ? py::len(dv) : 0);
             LossGradient g;
             g.dx = Unstack(dx, len);
             g.dv = Unstack(dv, len);
             if (g.dx.size() != g.dv.size()) {
               throw InvalidInputError("LossGradient: dx has " + std::to_string(g.dx.size()) + " rows and dv " +
                                       std::to_string(g.dv.size()) + ", expected the same (K + 1)");
             }
             return g;
           }),
           "dx"_a, "dv"_a = py::none(), "From (K+1) x 3n arrays (either may be None: zero).")
      .def_readwrite("dx", &LossGradient::dx)
      .def_readwrite("dv", &LossGradient::dv);

  py::class_<BackwardReport>(m, "BackwardReport")
      .def(py::init<>())
      .def_readonly("linear_iterations", &BackwardReport::linear_iterations)
      .def_readonly("fallbacks", &BackwardReport::fallbacks)
      .def_readonly("iterative_steps", &BackwardReport::iterative_steps)
      .def_readonly("direct_steps", &BackwardReport::direct_steps)
      .def_readonly("seconds", &BackwardReport::seconds);

  py::class_<RolloutGradient> gradient(m, "RolloutGradient", "dL/d(input) for every differentiable input.");
  gradient.def(py::init<>());
  EigenMember(gradient, "x0", &RolloutGradient::x0, "dL/dx_0 (3n); a view");
  EigenMember(gradient, "v0", &RolloutGradient::v0, "dL/dv_0 (3n); a view");
  gradient.def_readwrite("external_force", &RolloutGradient::external_force)
      .def_readwrite("activation", &RolloutGradient::activation)
      .def(
          "external_force_array", [](const RolloutGradient& g) { return Stack(g.external_force); },
          "dL/df_k as one K x 3n array.")
      .def(
          "activation_array", [](const RolloutGradient& g) { return Stack(g.activation); },
          "dL/da_k as one K x (muscles) array.")
      .def_readwrite("state_forces", &RolloutGradient::state_forces)
      .def_readwrite("youngs_modulus", &RolloutGradient::youngs_modulus)
      .def_readwrite("poissons_ratio", &RolloutGradient::poissons_ratio)
      .def_readwrite("density", &RolloutGradient::density)
      .def_readwrite("region_materials", &RolloutGradient::region_materials);
  EigenMember(gradient, "controller_parameters", &RolloutGradient::controller_parameters, "dL/dtheta; a view");
  EigenMember(gradient, "controller_memory", &RolloutGradient::controller_memory, "dL/dm_0; a view");
  gradient.def_readonly("report", &RolloutGradient::report);

  py::class_<InputDirection> direction(m, "InputDirection", "A direction in the space of a rollout's inputs.");
  direction.def(py::init<>());
  EigenMember(direction, "x0", &InputDirection::x0, "3n (m), or empty; a view");
  EigenMember(direction, "v0", &InputDirection::v0, "3n (m/s), or empty; a view");
  direction.def_readwrite("external_force", &InputDirection::external_force)
      .def_readwrite("activation", &InputDirection::activation)
      .def_readwrite("youngs_modulus", &InputDirection::youngs_modulus)
      .def_readwrite("poissons_ratio", &InputDirection::poissons_ratio)
      .def_readwrite("density", &InputDirection::density)
      .def_readwrite("region_materials", &InputDirection::region_materials)
      .def_readwrite("state_forces", &InputDirection::state_forces)
      .def_static("youngs_modulus_direction", &InputDirection::YoungsModulus)
      .def_static("poissons_ratio_direction", &InputDirection::PoissonsRatio)
      .def_static("density_direction", &InputDirection::Density)
      .def_static("region_youngs_modulus_direction", &InputDirection::RegionYoungsModulus, "region"_a, "num_regions"_a)
      .def_static("region_poissons_ratio_direction", &InputDirection::RegionPoissonsRatio, "region"_a, "num_regions"_a)
      .def_static("region_density_direction", &InputDirection::RegionDensity, "region"_a, "num_regions"_a);

  py::class_<TangentRollout>(m, "TangentRollout", "dx_k, dv_k (3n x P each) along P directions.")
      .def(py::init<>())
      .def_readonly("dx", &TangentRollout::dx, "list of K+1 arrays, 3n x P")
      .def_readonly("dv", &TangentRollout::dv)
      .def_readonly("report", &TangentRollout::report)
      .def_property_readonly("num_steps", &TangentRollout::num_steps)
      .def_property_readonly("num_directions", &TangentRollout::num_directions);
}

}  // namespace diffpd::python
