#include "bindings.hpp"
#include "cutting/surface_cutter.hpp"
#include "solve/cut_model_adapter.hpp"

namespace snede::bindings {

void bind_surface_cutting(py::module_& m) {
  py::class_<SurfaceCutter>(m, "SurfaceCutter")
      .def(py::init([](Mesh& mesh, Model* model, double eps_edge, double eps_entry, double eps_exit) {
             return std::make_unique<SurfaceCutter>(mesh, displacement_of(model, mesh, "SurfaceCutter"),
                                                    SurfaceCutterOptions{eps_edge, eps_entry, eps_exit});
           }),
           py::arg("mesh"), py::arg("model"), py::arg("eps_edge"), py::arg("eps_entry"), py::arg("eps_exit"),
           py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def("move", [](SurfaceCutter& c, const DoubleArray& segment) { return c.move(view(segment)); }, py::arg("segment"))
      .def("lift", &SurfaceCutter::lift)
      .def_property_readonly("active_nodes", [](const SurfaceCutter& c) { return to_array(c.active_nodes(), 1); })
      .def_property_readonly("cutting", &SurfaceCutter::cutting)
      .def_property_readonly("eps_edge", [](const SurfaceCutter& c) { return c.options().eps_edge; })
      .def_property_readonly("eps_entry", [](const SurfaceCutter& c) { return c.options().eps_entry; })
      .def_property_readonly("eps_exit", [](const SurfaceCutter& c) { return c.options().eps_exit; })
      .def("incision_edges", [](const SurfaceCutter& c) { return to_array(c.incision_edges(), 2); });
}

}  // namespace snede::bindings
