#include "bindings.hpp"
#include "record_binding.hpp"
#include "cutting/delaunay_cutter.hpp"
#include "cut_model_adapter.hpp"

namespace snede::bindings {

void bind_planar_cutting(py::module_& m) {
  py::register_exception<IncisionLost>(m, "IncisionLost", error_bases(PyExc_RuntimeError));
  bind_record<PlanarCutResult>(
      m, "PlanarCutResult",
      "What one ``move`` (or a whole ``cut``) did: edge ``flips``, ``nodes_removed`` near the active node,\n"
      "``nodes_inserted`` (entry, exit and incision splits), ``incision_splits`` (Figure 5.5),\n"
      "``edges_contracted`` after exits (Figure 5.7), ``entries``, ``exits``, on surfaces ``branches``\n"
      "(Figure 5.14) and ``annihilations`` (incisions meeting, Figure 5.13), moves that left the active node\n"
      "short of the scalpel (``stuck``), the triangle counts before and after, and the time in ``seconds``.\n"
      "``a + b``: counts and times add, ``triangles_after`` is ``b``'s.")
      .def("__str__", [](const PlanarCutResult& r) { return summary(r); });
  m.attr("PlanarCutReport") = m.attr("PlanarCutResult");  // its name before issue 51: old pickles load

  bind_record<DelaunayCutterOptions>(
      m, "DelaunayCutterOptions",
      "A DelaunayCutter's settings (snede.DelaunayCutter documents each); the engine's struct. A threshold of\n"
      "0 is the thesis's default from the mean edge length; the cutter refuses values out of range when made.");

  py::class_<DelaunayCutter> cutter(m, "DelaunayCutter");
  def_delaunay_cutter_common(cutter);
  cutter
      .def(py::init([](Mesh& mesh, Model* model, const DelaunayCutterOptions& options) {
             return std::make_unique<DelaunayCutter>(mesh, displacement_of(model, mesh, "DelaunayCutter"), options);
           }),
           py::arg("mesh"), py::arg("model"), py::arg("options"), py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def("move", [](DelaunayCutter& c, const DoubleArray& point) { return c.move(view(point)); }, py::arg("point"))
      .def_property_readonly("active_node", &DelaunayCutter::active_node);
}

}  // namespace snede::bindings
