// The native part of the Python package diffpd (python/diffpd/__init__.py
// re-exports it).
#include "bindings.h"

PYBIND11_MODULE(_diffpd, m) {
  m.doc() = "DiffPD: differentiable projective dynamics (native module; use the package diffpd)";
  using namespace diffpd::python;
  BindErrors(m);
  BindMesh(m);
  BindMaterial(m);
  BindScene(m);
  BindOptions(m);
  BindRollout(m);
  BindController(m);
  BindSimulator(m);
  BindMotion(m);
#ifdef DIFFPD_PYTHON_WITH_PROBLEMS
  BindProblems(m);
#endif
}
