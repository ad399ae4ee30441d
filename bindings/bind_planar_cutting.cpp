#include "bindings.hpp"
#include "cutting/delaunay_cutter.hpp"
#include "solve/cut_model_adapter.hpp"

namespace snede::bindings {

void bind_planar_cutting(py::module_& m) {
  py::register_exception<IncisionLost>(m, "IncisionLost", PyExc_RuntimeError);
  py::class_<PlanarCutReport>(m, "PlanarCutReport")
      .def(py::init<>())
      .def("add", &PlanarCutReport::add, py::arg("later"))
      .def_readwrite("moves", &PlanarCutReport::moves)
      .def_readwrite("flips", &PlanarCutReport::flips)
      .def_readwrite("nodes_removed", &PlanarCutReport::nodes_removed)
      .def_readwrite("nodes_inserted", &PlanarCutReport::nodes_inserted)
      .def_readwrite("incision_splits", &PlanarCutReport::incision_splits)
      .def_readwrite("edges_contracted", &PlanarCutReport::edges_contracted)
      .def_readwrite("entries", &PlanarCutReport::entries)
      .def_readwrite("exits", &PlanarCutReport::exits)
      .def_readwrite("branches", &PlanarCutReport::branches)
      .def_readwrite("annihilations", &PlanarCutReport::annihilations)
      .def_readwrite("stuck", &PlanarCutReport::stuck)
      .def_readwrite("triangles_before", &PlanarCutReport::triangles_before)
      .def_readwrite("triangles_after", &PlanarCutReport::triangles_after)
      .def_readwrite("seconds", &PlanarCutReport::seconds);

  py::class_<DelaunayCutter>(m, "DelaunayCutter")
      .def(py::init([](Mesh& mesh, Model* model, double eps_edge, double eps_entry, double eps_exit, double angle) {
             return std::make_unique<DelaunayCutter>(mesh, displacement_of(model, mesh, "DelaunayCutter"),
                                                     DelaunayCutterOptions{eps_edge, eps_entry, eps_exit, angle});
           }),
           py::arg("mesh"), py::arg("model"), py::arg("eps_edge"), py::arg("eps_entry"), py::arg("eps_exit"),
           py::arg("short_edge_angle"), py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def("move", [](DelaunayCutter& c, const DoubleArray& point) { return c.move(view(point)); }, py::arg("point"))
      .def("lift", &DelaunayCutter::lift)
      .def_property_readonly("active_node", &DelaunayCutter::active_node)
      .def_property_readonly("cutting", &DelaunayCutter::cutting)
      .def_property_readonly("eps_edge", [](const DelaunayCutter& c) { return c.options().eps_edge; })
      .def_property_readonly("eps_entry", [](const DelaunayCutter& c) { return c.options().eps_entry; })
      .def_property_readonly("eps_exit", [](const DelaunayCutter& c) { return c.options().eps_exit; })
      .def("incision_edges", [](const DelaunayCutter& c) { return to_array(c.incision_edges(), 2); });
}

}  // namespace snede::bindings
