#include "bindings.hpp"
#include "needle/needle_insertion.hpp"

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
                                             double static_factor, std::optional<double> h_ref, double radius,
                                             int max_rearrangements, int solves_per_update, bool extrapolate,
                                             const std::string& method, double rtol, const std::string& criterion,
                                             double round_tolerance, int max_iterations, const std::string& prefix,
                                             const OptionList& petsc_options) {
  NeedleOptions options;
  options.static_factor = static_factor;
  options.h_ref = h_ref;
  options.radius = radius;
  options.max_rearrangements = max_rearrangements;
  options.solves_per_update = solves_per_update;
  options.extrapolate = extrapolate;
  return std::make_unique<NeedleInsertion>(
      model, bisection, point_of(entry, model.dim(), "entry"), point_of(direction, model.dim(), "direction"), friction,
      options,
      static_options(method, rtol, criterion, round_tolerance, max_iterations, prefix, petsc_options));
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

  py::class_<NeedleStepReport>(m, "NeedleStepReport")
      .def_readonly("rearrangements", &NeedleStepReport::rearrangements)
      .def_readonly("slipped", &NeedleStepReport::slipped)
      .def_readonly("stuck", &NeedleStepReport::stuck)
      .def_readonly("released", &NeedleStepReport::released)
      .def_readonly("intercepted", &NeedleStepReport::intercepted)
      .def_readonly("cells_split", &NeedleStepReport::cells_split)
      .def_readonly("solver_iterations", &NeedleStepReport::solver_iterations)
      .def_readonly("max_solver_iterations", &NeedleStepReport::max_solver_iterations)
      .def_readonly("converged", &NeedleStepReport::converged)
      .def_readonly("settled", &NeedleStepReport::settled)
      .def_readonly("reason", &NeedleStepReport::reason)
      .def_readonly("seconds", &NeedleStepReport::seconds);

  py::class_<NeedleInsertion>(m, "NeedleInsertion")
      .def(py::init(&make_needle), py::arg("model"), py::arg("bisection"), py::arg("entry"), py::arg("direction"),
           py::arg("friction"), py::arg("static_factor"), py::arg("h_ref"), py::arg("radius"), py::arg("max_rearrangements"), py::arg("solves_per_update"), py::arg("extrapolate"),
           py::arg("method"), py::arg("rtol"), py::arg("criterion"), py::arg("round_tolerance"),
           py::arg("max_iterations"), py::arg("options_prefix"), py::arg("petsc_options"), py::keep_alive<1, 2>(),
           py::keep_alive<1, 3>())
      .def("advance", &NeedleInsertion::advance, py::arg("distance"))
      .def("settle", &NeedleInsertion::settle)
      .def_property_readonly("depth", &NeedleInsertion::depth)
      .def_property_readonly("surface_depth", &NeedleInsertion::surface_depth)
      .def_property_readonly("preconditioner_fills", [](NeedleInsertion& n) { return n.solver().preconditioner_fills(); })
      .def_property_readonly("multigrid_builds", [](NeedleInsertion& n) { return n.solver().multigrid_builds(); })
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
