// The parts of the Python module diffpd._diffpd, one concept per file; each
// Bind* function adds its classes and functions to the module. module.cc
// calls them in dependency order (a class must be registered before a later
// signature names it).
#pragma once

#include <string>

#include <pybind11/pybind11.h>

namespace diffpd::python {

void BindErrors(pybind11::module_& m);      // errors_bindings.cc
void BindMesh(pybind11::module_& m);        // mesh_bindings.cc
void BindMaterial(pybind11::module_& m);    // material_bindings.cc
void BindScene(pybind11::module_& m);       // scene_bindings.cc
void BindOptions(pybind11::module_& m);     // options_bindings.cc
void BindRollout(pybind11::module_& m);     // rollout_bindings.cc
void BindController(pybind11::module_& m);  // controller_bindings.cc
void BindSimulator(pybind11::module_& m);   // simulator_bindings.cc
void BindMotion(pybind11::module_& m);      // motion_bindings.cc
void BindProblems(pybind11::module_& m);    // problems_bindings.cc (only with the problems library)

// A read-write property of an Eigen member that shares the object's memory:
// reading it gives a NumPy array viewing the member (writes through, kept
// alive by the object), assigning copies a new value in (any shape change is
// the caller's choice).
template <class Class, class Member, class... Options>
void EigenMember(pybind11::class_<Class, Options...>& cls, const char* name, Member Class::*member, const char* doc) {
  cls.def_property(
      name, [member](Class& self) -> Member& { return self.*member; },
      [member](Class& self, const Member& value) { self.*member = value; },
      pybind11::return_value_policy::reference_internal, doc);
}

// Makes str() of an enum's values the library's name for them (ToString:
// "pd", "newton-cholesky", ...), replacing py::enum_'s "Type.VALUE"
// (a method defined with .def would only be tried after that one).
template <class Enum>
void LibraryNames(pybind11::enum_<Enum> cls) {
  cls.attr("__str__") = pybind11::cpp_function([](Enum value) { return std::string(ToString(value)); },
                                               pybind11::name("__str__"), pybind11::is_method(cls));
}

}  // namespace diffpd::python
