// Materials and energy densities (diffpd/material.h).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/material.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {

void BindMaterial(py::module_& m) {
  py::class_<MaterialParameters>(m, "MaterialParameters", "Young's modulus (Pa), Poisson's ratio and density (kg/m^3).")
      .def(py::init([](double E, double nu, double rho) {
             return MaterialParameters{E, nu, rho};
           }),
           "youngs_modulus"_a = 1e6, "poissons_ratio"_a = 0.45, "density"_a = 1e3)
      .def_readwrite("youngs_modulus", &MaterialParameters::youngs_modulus)
      .def_readwrite("poissons_ratio", &MaterialParameters::poissons_ratio)
      .def_readwrite("density", &MaterialParameters::density)
      .def("validate", &MaterialParameters::Validate)
      .def_property_readonly("mu", &MaterialParameters::mu)
      .def_property_readonly("lam", &MaterialParameters::lambda)
      .def("__repr__", [](const MaterialParameters& p) {
        return "MaterialParameters(youngs_modulus=" + py::repr(py::float_(p.youngs_modulus)).cast<std::string>() +
               ", poissons_ratio=" + py::repr(py::float_(p.poissons_ratio)).cast<std::string>() +
               ", density=" + py::repr(py::float_(p.density)).cast<std::string>() + ")";
      });
  py::class_<MaterialComponents>(m, "MaterialComponents", "One number per material parameter (E, nu, rho).")
      .def(py::init([](double E, double nu, double rho) {
             return MaterialComponents{E, nu, rho};
           }),
           "youngs_modulus"_a = 0.0, "poissons_ratio"_a = 0.0, "density"_a = 0.0)
      .def_readwrite("youngs_modulus", &MaterialComponents::youngs_modulus)
      .def_readwrite("poissons_ratio", &MaterialComponents::poissons_ratio)
      .def_readwrite("density", &MaterialComponents::density);

  LibraryNames(py::enum_<ElasticEnergy>(m, "ElasticEnergy", "Elastic energy densities (diffpd/material.h).")
                   .value("LINEAR", ElasticEnergy::kLinear)
                   .value("COROTATED", ElasticEnergy::kCorotated)
                   .value("NEOHOOKEAN", ElasticEnergy::kNeoHookean)
                   .value("PD_COROTATED", ElasticEnergy::kPdCorotated)
                   .value("PD_VOLUME", ElasticEnergy::kPdVolume));
  m.def("is_projective", &IsProjective, "energy"_a);
  m.def("energy_density", &EnergyDensity, "energy"_a, "F"_a, "mu"_a, "lam"_a, "Psi(F), J/m^3.");
  m.def("first_piola_stress", &FirstPiolaStress, "energy"_a, "F"_a, "mu"_a, "lam"_a, "P = dPsi/dF, Pa (3 x 3).");
  m.def("stress_differential", &StressDifferential, "energy"_a, "F"_a, "mu"_a, "lam"_a,
        "dP/dF (9 x 9, column-major flattening).");
}

}  // namespace diffpd::python
