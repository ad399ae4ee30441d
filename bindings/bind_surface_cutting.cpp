#include "bindings.hpp"
#include "record_binding.hpp"
#include "cutting/surface_cutter.hpp"
#include "cut_model_adapter.hpp"

namespace snede::bindings {

void bind_surface_cutting(py::module_& m) {
  bind_record<SurfaceCutterOptions>(
      m, "SurfaceCutterOptions",
      "A SurfaceCutter's settings (snede.SurfaceCutter documents each); the engine's struct. A threshold of 0\n"
      "is the thesis's default from the mean edge length; the cutter refuses values out of range when made.");

  py::class_<SurfaceCutter> cutter(m, "SurfaceCutter");
  def_delaunay_cutter_common(cutter);
  cutter
      .def(py::init([](Mesh& mesh, Model* model, const SurfaceCutterOptions& options) {
             return std::make_unique<SurfaceCutter>(mesh, displacement_of(model, mesh, "SurfaceCutter"), options);
           }),
           py::arg("mesh"), py::arg("model"), py::arg("options"), py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def("move", [](SurfaceCutter& c, const DoubleArray& segment) { return c.move(view(segment)); }, py::arg("segment"))
      .def_property_readonly("active_nodes", [](const SurfaceCutter& c) { return to_array(c.active_nodes(), 1); });
}

}  // namespace snede::bindings
