// Solver options and their enums (diffpd/solver_options.h). Every field of
// SolverOptions is an attribute with the C++ default; validate() raises
// InvalidInputError as SolverOptions::Validate does.
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/solver_options.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {

void BindOptions(py::module_& m) {
  LibraryNames(py::enum_<Method>(m, "Method", "Time integrators; str() gives the command-line name.")
                   .value("SEMI_IMPLICIT", Method::kSemiImplicit)
                   .value("NEWTON_CHOLESKY", Method::kNewtonCholesky)
                   .value("NEWTON_PCG", Method::kNewtonPcg)
                   .value("PD", Method::kPd)
                   .value("PD_LBFGS", Method::kPdLbfgs)
                   .value("NEWTON_LDLT", Method::kNewtonLdlt));
  m.def("parse_method", &ParseMethod, "name"_a, "The Method called `name` (\"pd\", \"newton-cholesky\", ...).");
  py::enum_<PcgPreconditioner>(m, "PcgPreconditioner")
      .value("JACOBI", PcgPreconditioner::kJacobi)
      .value("INCOMPLETE_CHOLESKY", PcgPreconditioner::kIncompleteCholesky);
  py::enum_<ToleranceReference>(m, "ToleranceReference")
      .value("START_RESIDUAL", ToleranceReference::kStartResidual)
      .value("INERTIA", ToleranceReference::kInertia);
  py::enum_<PdBackwardMethod>(m, "PdBackwardMethod")
      .value("FIXED_POINT", PdBackwardMethod::kFixedPoint)
      .value("LBFGS", PdBackwardMethod::kLbfgs)
      .value("CONJUGATE_GRADIENT", PdBackwardMethod::kConjugateGradient);
  LibraryNames(py::enum_<AdjointSolver>(m, "AdjointSolver")
                   .value("AUTO", AdjointSolver::kAuto)
                   .value("ITERATIVE", AdjointSolver::kIterative)
                   .value("DIRECT", AdjointSolver::kDirect));
  m.def("parse_adjoint_solver", &ParseAdjointSolver, "name"_a);
  m.def("max_solver_threads", &MaxSolverThreads, "The most threads SolverOptions.num_threads may ask for.");

  using O = SolverOptions;
  py::class_<O> options(m, "SolverOptions", "Options of the time integrators (diffpd/solver_options.h).");
  options.def(py::init<>())
      .def(py::init([](py::kwargs kwargs) {
             O result;
             py::object self = py::cast(&result, py::return_value_policy::reference);
             for (const auto& item : kwargs) {
               const std::string key = item.first.cast<std::string>();
               if (!py::hasattr(self, key.c_str()) || key.rfind("_", 0) == 0) {
                 throw py::type_error("SolverOptions has no field '" + key + "'");
               }
               py::setattr(self, item.first, item.second);
             }
             return result;
           }),
           "Options with the given fields set, e.g. SolverOptions(method=Method.NEWTON_CHOLESKY, time_step=0.005).")
      .def_readwrite("method", &O::method)
      .def_readwrite("time_step", &O::time_step)
      .def_readwrite("abs_tolerance", &O::abs_tolerance)
      .def_readwrite("rel_tolerance", &O::rel_tolerance)
      .def_readwrite("tolerance_reference", &O::tolerance_reference)
      .def_readwrite("max_iterations", &O::max_iterations)
      .def_readwrite("bound_step_energy", &O::bound_step_energy)
      .def_readwrite("armijo_c", &O::armijo_c)
      .def_readwrite("max_line_search_steps", &O::max_line_search_steps)
      .def_readwrite("accept_rounding_floor", &O::accept_rounding_floor)
      .def_readwrite("pcg_preconditioner", &O::pcg_preconditioner)
      .def_readwrite("pcg_rel_tolerance", &O::pcg_rel_tolerance)
      .def_readwrite("pcg_max_iterations", &O::pcg_max_iterations)
      .def_readwrite("lbfgs_history", &O::lbfgs_history)
      .def_readwrite("lbfgs_weight_scale", &O::lbfgs_weight_scale)
      .def_readwrite("pd_lbfgs_newton_fallback", &O::pd_lbfgs_newton_fallback)
      .def_readwrite("rigid_mode_correction", &O::rigid_mode_correction)
      .def_readwrite("adjoint_solver", &O::adjoint_solver)
      .def_readwrite("pd_backward", &O::pd_backward)
      .def_readwrite("backward_rel_tolerance", &O::backward_rel_tolerance)
      .def_readwrite("backward_tolerance_factor", &O::backward_tolerance_factor)
      .def_readwrite("backward_max_iterations", &O::backward_max_iterations)
      .def_readwrite("adjoint_guess_solutions", &O::adjoint_guess_solutions)
      .def_readwrite("max_extent_ratio", &O::max_extent_ratio)
      .def_readwrite("pd_factor_copy_max_bytes", &O::pd_factor_copy_max_bytes)
      .def_readwrite("svd_warm_start", &O::svd_warm_start)
      .def_readwrite("num_threads", &O::num_threads)
      .def_readwrite("verbosity", &O::verbosity)
      .def("validate", &O::Validate);
}

}  // namespace diffpd::python
