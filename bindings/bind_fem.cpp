#include "bindings.hpp"
#include "fem/elastic_body.hpp"

#include <pybind11/stl.h>

#include <cstdio>
#include <cstdlib>
#include <optional>

namespace snede::bindings {

Material material_from(const py::handle& object) {
  if (py::isinstance<LinearElastic>(object)) return object.cast<LinearElastic>();
  if (py::isinstance<StVenantKirchhoff>(object)) return object.cast<StVenantKirchhoff>();
  if (py::isinstance<NeoHookean>(object)) return object.cast<NeoHookean>();
  if (py::isinstance<VerondaWestmann>(object)) return object.cast<VerondaWestmann>();
  throw py::type_error("material must be LinearElastic, StVenantKirchhoff, NeoHookean or VerondaWestmann, got " +
                       py::str(py::type::of(object)).cast<std::string>());
}

namespace {



// Runs an evaluation that fills a (n_points, dim) array, raising DomainError on overflow.
template <class Evaluate>
py::array_t<double> nodal_result(const ElasticBody& body, Evaluate&& evaluate) {
  std::vector<double> out(body.n_dofs());
  EvaluationReport report;
  evaluate(std::span<double>(out), report);
  throw_if_domain_error(report);
  return to_array(out, body.dim());
}

double energy_of(const ElasticBody& body, const DoubleArray& u) {
  EvaluationReport report;
  const double value = body.energy(view(u), report);
  throw_if_domain_error(report);
  return value;
}

py::array_t<double> forces_of(const ElasticBody& body, const DoubleArray& u) {
  return nodal_result(body, [&](std::span<double> f, EvaluationReport& r) { body.internal_forces(view(u), f, r); });
}

py::array_t<double> tangent_of(const ElasticBody& body, const DoubleArray& u, const DoubleArray& d) {
  return nodal_result(body, [&](std::span<double> out, EvaluationReport& r) { body.tangent_apply(view(u), view(d), out, r); });
}

py::array_t<double> stress_of(const ElasticBody& body, const DoubleArray& u) {
  const std::vector<double> s = body.element_stress(view(u));
  const int stress_dim = body.mesh().cell_dim();  // a membrane's stress is in-plane, 2 × 2
  py::array_t<double> out({static_cast<py::ssize_t>(s.size() / (stress_dim * stress_dim)),
                           static_cast<py::ssize_t>(stress_dim), static_cast<py::ssize_t>(stress_dim)});
  std::copy(s.begin(), s.end(), out.mutable_data());
  return out;
}

py::array_t<double> stiffness_of(const ElasticBody& body, ElementId e, const DoubleArray& u) {
  return to_array(body.element_stiffness(e, view(u)), (body.mesh().cell_dim() + 1) * body.dim());
}

// std::variant's caster needs default-constructible alternatives; materials have none.
std::unique_ptr<ElasticBody> make_body(Mesh& mesh, const py::handle& material, double density, double thickness,
                                       const std::string& formulation) {
  return std::make_unique<ElasticBody>(mesh, material_from(material), density, thickness, parse_formulation(formulation));
}

py::dict flops_of(const ElasticBody& body) {
  const KernelFlops f = body.flops_per_element();
  py::dict out;
  out["energy"] = f.energy;
  out["force"] = f.force;
  out["tangent"] = f.tangent;
  out["functions"] = f.functions;
  return out;
}

// x as Python prints it after rounding to 15 significant digits: E and ν come back from the
// Lamé parameters with round-off (0.30000000000000004), which a repr should not show.
std::string rounded_repr(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", x);
  return py::repr(py::float_(std::strtod(text, nullptr))).cast<std::string>();
}

// VerondaWestmann(E, nu, gamma) with a message, not pybind11's list of signatures, for a
// missing ν or γ.
VerondaWestmann make_veronda_westmann(double E, std::optional<double> nu, std::optional<double> gamma) {
  if (!nu || !gamma)
    throw std::invalid_argument(std::string("VerondaWestmann(E, nu, gamma) needs ") + (nu ? "" : "nu, Poisson's ratio, and ") +
                                "gamma, its exponential stiffening (dimensionless, > 0; e.g. 8 as in §4.3)");
  return VerondaWestmann(E, *nu, *gamma);
}

// A material's class with what every material shows: Lamé parameters, E, ν and a repr
// naming them (γ too where there is one).
template <class M>
py::class_<M> bind_material(py::module_& m, const char* name) {
  py::class_<M> material(m, name);
  material.def_property_readonly("lame", [](const M& s) { return py::make_tuple(s.lame.lambda, s.lame.mu); })
      .def_property_readonly("E", [](const M& s) { return young_modulus(s.lame); })
      .def_property_readonly("nu", [](const M& s) { return poisson_ratio(s.lame); })
      .def("__repr__", [name](const M& s) {
        std::string text =
            std::string(name) + "(E=" + rounded_repr(young_modulus(s.lame)) + ", nu=" + rounded_repr(poisson_ratio(s.lame));
        if constexpr (requires { s.gamma; }) text += ", gamma=" + rounded_repr(s.gamma);
        return text + ")";
      });
  return material;
}

}  // namespace

void bind_fem(py::module_& m) {
  py::register_exception<DomainError>(m, "DomainError", error_bases(PyExc_ArithmeticError));
  auto linear = bind_material<LinearElastic>(m, "LinearElastic");
  linear.def(py::init<double, double>(), py::arg("E"), py::arg("nu"));
  auto stvk = bind_material<StVenantKirchhoff>(m, "StVenantKirchhoff");
  stvk.def(py::init<double, double>(), py::arg("E"), py::arg("nu"));
  auto neo = bind_material<NeoHookean>(m, "NeoHookean");
  neo.def(py::init<double, double>(), py::arg("E"), py::arg("nu"));
  auto veronda = bind_material<VerondaWestmann>(m, "VerondaWestmann");
  veronda.def(py::init(&make_veronda_westmann), py::arg("E"), py::arg("nu") = py::none(), py::arg("gamma") = py::none())
      .def_readonly("gamma", &VerondaWestmann::gamma);

  m.def("formulations", [] {
    std::vector<std::string> names(formulation_names.begin(), formulation_names.end());
    return names;
  });
  py::class_<ElasticBody>(m, "ElasticBody")
      .def(py::init(&make_body), py::arg("mesh"), py::arg("material"), py::arg("density"),
           py::arg("thickness"), py::arg("formulation") = "p1", py::keep_alive<1, 2>())
      .def_property_readonly("dim", &ElasticBody::dim)
      .def_property_readonly("formulation", [](const ElasticBody& b) { return std::string(name_of(b.formulation())); })
      .def_property_readonly("density", &ElasticBody::density)
      .def_property_readonly("thickness", &ElasticBody::thickness)
      .def("energy", &energy_of, py::arg("u"))
      .def("internal_forces", &forces_of, py::arg("u"))
      .def("tangent_apply", &tangent_of, py::arg("u"), py::arg("d"))
      .def("inverted_elements", [](const ElasticBody& b, const DoubleArray& u) { return b.inverted_elements(view(u)); })
      .def("element_stress", &stress_of, py::arg("u"))
      .def("element_stiffness", &stiffness_of, py::arg("element"), py::arg("u"))
      .def("lumped_mass", &ElasticBody::lumped_mass)
      .def("gravity_forces", [](const ElasticBody& b, const DoubleArray& g) { return to_array(b.gravity_forces(view(g)), b.dim()); })
      .def("flops_per_element", &flops_of);
}

}  // namespace snede::bindings
