#include "bindings.hpp"
#include "cutting/surface_cutter.hpp"
#include "cut_model_adapter.hpp"

namespace snede::bindings {

void bind_surface_cutting(py::module_& m) {
  py::class_<SurfaceCutter> cutter(m, "SurfaceCutter");
  def_delaunay_cutter_common(cutter);
  cutter
      .def(py::init([](Mesh& mesh, Model* model, double eps_edge, double eps_entry, double eps_exit) {
             return std::make_unique<SurfaceCutter>(mesh, displacement_of(model, mesh, "SurfaceCutter"),
                                                    SurfaceCutterOptions{eps_edge, eps_entry, eps_exit});
           }),
           py::arg("mesh"), py::arg("model"), py::arg("eps_edge"), py::arg("eps_entry"), py::arg("eps_exit"),
           py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def("move", [](SurfaceCutter& c, const DoubleArray& segment) { return c.move(view(segment)); }, py::arg("segment"))
      .def_property_readonly("active_nodes", [](const SurfaceCutter& c) { return to_array(c.active_nodes(), 1); });
}

}  // namespace snede::bindings
