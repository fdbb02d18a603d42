// The library's exceptions as Python exceptions:
//   diffpd.Error                          base of both
//   diffpd.InvalidInputError(Error, ValueError)    InvalidInputError
//   diffpd.SolverError(Error, RuntimeError)        SolverError; .status is a SolverStatus
// Each carries the library's message unchanged (str(e) == what()).
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "diffpd/error.h"

namespace py = pybind11;

namespace diffpd::python {
namespace {

// Owned by the module for the life of the interpreter (never released).
PyObject* g_error = nullptr;
PyObject* g_invalid_input_error = nullptr;
PyObject* g_solver_error = nullptr;

PyObject* NewException(const char* name, PyObject* first_base, PyObject* second_base, const char* doc) {
  PyObject* bases = second_base ? PyTuple_Pack(2, first_base, second_base) : PyTuple_Pack(1, first_base);
  PyObject* type = PyErr_NewExceptionWithDoc(name, doc, bases, nullptr);
  Py_DECREF(bases);
  if (!type) throw py::error_already_set();
  return type;
}

}  // namespace

void BindErrors(py::module_& m) {
  LibraryNames(py::enum_<SolverStatus>(m, "SolverStatus", "Why a numerical solve failed (diffpd/error.h).")
                   .value("CONVERGED", SolverStatus::kConverged)
                   .value("MAX_ITERATIONS", SolverStatus::kMaxIterations)
                   .value("LINE_SEARCH_FAILED", SolverStatus::kLineSearchFailed)
                   .value("NON_FINITE", SolverStatus::kNonFinite)
                   .value("FACTORIZATION_FAILED", SolverStatus::kFactorizationFailed)
                   .value("INVERTED_ELEMENT", SolverStatus::kInvertedElement)
                   .value("DIVERGED", SolverStatus::kDiverged)
                   .value("ACTIVE_SET_NOT_CONVERGED", SolverStatus::kActiveSetNotConverged)
                   .value("CONTACT_ENERGY_GAIN", SolverStatus::kContactEnergyGain));

  g_error = NewException("diffpd.Error", PyExc_Exception, nullptr, "Base of the DiffPD library's exceptions.");
  g_invalid_input_error = NewException("diffpd.InvalidInputError", g_error, PyExc_ValueError,
                                       "Invalid input: the message names the input, its value and the allowed range.");
  g_solver_error = NewException("diffpd.SolverError", g_error, PyExc_RuntimeError,
                                "A numerical solve failed; `status` (SolverStatus) says why.");
  m.add_object("Error", py::handle(g_error));
  m.add_object("InvalidInputError", py::handle(g_invalid_input_error));
  m.add_object("SolverError", py::handle(g_solver_error));

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidInputError& e) {
      PyErr_SetString(g_invalid_input_error, e.what());
    } catch (const SolverError& e) {
      py::object error = py::reinterpret_borrow<py::object>(g_solver_error)(e.what());
      error.attr("status") = py::cast(e.status());
      PyErr_SetObject(g_solver_error, error.ptr());
    }
  });
}

}  // namespace diffpd::python
