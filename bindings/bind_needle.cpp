#include "bindings.hpp"
#include "needle/needle_insertion.hpp"
#include "record_binding.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {
namespace {

Point point_of(const DoubleArray& a, int dim, const char* name) {
  if (a.size() != dim)
    throw std::invalid_argument(std::string(name) + " must have " + std::to_string(dim) + " components for this " +
                                std::to_string(dim) + "-D body, got " + std::to_string(a.size()));
  Point x{0, 0, 0};
  std::copy_n(a.data(), dim, x.begin());
  return x;
}

std::vector<double> point_vector(const Point& x, int dim) { return {x.begin(), x.begin() + dim}; }

std::unique_ptr<NeedleInsertion> make_needle(Model& model, Bisection* bisection, const DoubleArray& entry,
                                             const DoubleArray& direction, const FrictionProfile& friction,
                                             const NeedleOptions& options, const StaticOptions& solver_options) {
  return std::make_unique<NeedleInsertion>(model, bisection, point_of(entry, model.dim(), "entry"),
                                           point_of(direction, model.dim(), "direction"), friction, options,
                                           solver_options);
}

py::array_t<double> node_field(const NeedleInsertion& needle, double NeedleNode::*field) {
  std::vector<double> values;
  for (const NeedleNode& node : needle.needle_nodes()) values.push_back(node.*field);
  return to_array(values, 1).reshape({static_cast<py::ssize_t>(values.size())});
}

}  // namespace

void bind_needle(py::module_& m) {
  py::class_<FrictionProfile>(m, "FrictionProfile")
      .def(py::init<std::vector<double>, std::vector<double>>(), py::arg("distance_from_tip"),
           py::arg("force_per_length"))
      .def("at", &FrictionProfile::at, py::arg("distance"))
      .def("integral", &FrictionProfile::integral, py::arg("a"), py::arg("b"))
      .def_property_readonly("distances", &FrictionProfile::distances)
      .def_property_readonly("force_per_length", &FrictionProfile::force_per_length);

  bind_record<NeedleOptions>(m, "NeedleOptions",
                             "A needle insertion's settings (snede.NeedleInsertion documents each); the engine's struct.")
      .def_readonly_static("default_radius", &NeedleOptions::default_radius);

  bind_record<NeedleStepResult>(
      m, "NeedleStepResult",
      "One update (§6.7). ``rearrangements`` counts the solves (each followed by a rearrangement of the\n"
      "needle nodes); ``slipped``/``stuck``/``released``/``intercepted`` count node state changes;\n"
      "``converged`` is False if a solve did not converge (``reason`` ``SOLVE_<PETSc reason>``) or the\n"
      "rearrangements did not settle within ``max_rearrangements`` (``DIVERGED_REARRANGEMENT_LIMIT``).\n"
      "``settled`` is False when node states still had to change at the end (with ``solves_per_update``,\n"
      "carried into the next update).");
  m.attr("NeedleStepReport") = m.attr("NeedleStepResult");  // its name before issue 51: old pickles load

  py::class_<NeedleInsertion>(m, "NeedleInsertion")
      .def(py::init(&make_needle), py::arg("model"), py::arg("bisection"), py::arg("entry"), py::arg("direction"),
           py::arg("friction"), py::arg("options"), py::arg("solver_options"), py::keep_alive<1, 2>(),
           py::keep_alive<1, 3>())
      .def("advance", &NeedleInsertion::advance, py::arg("distance"), py::call_guard<py::gil_scoped_release>())
      .def("settle", &NeedleInsertion::settle)
      .def_static("default_solver_options", &NeedleInsertion::default_solver_options)
      .def_property_readonly("radius", &NeedleInsertion::radius)
      .def_property_readonly("options", &NeedleInsertion::options)
      .def_property_readonly("solver_options", [](NeedleInsertion& n) { return n.solver().options(); })
      .def_property_readonly("depth", &NeedleInsertion::depth)
      .def_property_readonly("surface_depth", &NeedleInsertion::surface_depth)
      .def_property_readonly("preconditioner_fills", [](NeedleInsertion& n) { return n.solver().preconditioner_fills(); })
      .def_property_readonly("multigrid_builds", [](NeedleInsertion& n) { return n.solver().multigrid_builds(); })
      .def_property_readonly("multigrid_edits", [](NeedleInsertion& n) { return n.solver().multigrid_edits(); })
      .def_property_readonly("multigrid_source", [](NeedleInsertion& n) { return n.solver().multigrid_source(); })
      .def_property_readonly("multigrid_unknowns", [](NeedleInsertion& n) { return n.solver().multigrid_unknowns(); })
      .def_property_readonly("tip", [](const NeedleInsertion& n) { return point_vector(n.tip(), n.dim()); })
      .def_property_readonly("entry", [](const NeedleInsertion& n) { return point_vector(n.entry(), n.dim()); })
      .def_property_readonly("direction", [](const NeedleInsertion& n) { return point_vector(n.direction(), n.dim()); })
      .def_property_readonly("needle_nodes", [](const NeedleInsertion& n) {
        std::vector<VertexId> ids;
        for (const NeedleNode& node : n.needle_nodes()) ids.push_back(node.vertex);
        return ids;
      })
      .def_property_readonly("sticking", [](const NeedleInsertion& n) {
        std::vector<bool> flags;
        for (const NeedleNode& node : n.needle_nodes()) flags.push_back(node.sticking);
        return flags;
      })
      .def_property_readonly("d_perp", [](const NeedleInsertion& n) { return node_field(n, &NeedleNode::d_perp); })
      .def_property_readonly("d_needle", [](const NeedleInsertion& n) { return node_field(n, &NeedleNode::d_needle); })
      .def_property_readonly("dynamic_thresholds",
                             [](const NeedleInsertion& n) { return node_field(n, &NeedleNode::dynamic_threshold); })
      .def_property_readonly("static_thresholds",
                             [](const NeedleInsertion& n) { return node_field(n, &NeedleNode::static_threshold); })
      .def_property_readonly("friction", [](const NeedleInsertion& n) { return node_field(n, &NeedleNode::friction); })
      .def("needle_forces", [](NeedleInsertion& n) { return to_array(n.needle_forces(), n.dim()); });
}

}  // namespace snede::bindings
