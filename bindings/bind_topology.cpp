#include "bindings.hpp"
#include "mesh/mesh.hpp"
#include "topology/bisection.hpp"
#include "topology/refine_around.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {
namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::span<const double> point_of(const DoubleArray& x) { return {x.data(), static_cast<std::size_t>(x.size())}; }

}  // namespace

void bind_topology(py::module_& m) {
  py::class_<Bisection>(m, "Bisection")
      .def(py::init<Mesh&>(), py::arg("mesh"), py::keep_alive<1, 2>())
      .def("refine_uniform", &Bisection::refine_uniform, py::arg("levels"))
      .def("refine_around",
           [](Bisection& b, const DoubleArray& x, double h) { return refine_around(b, point_of(x), h); },
           py::arg("point"), py::arg("h"))
      .def("bisect", &Bisection::bisect, py::arg("element"))
      .def("locate_all", [](const Bisection& b, const DoubleArray& x) { return b.hierarchy().locate_all(point_of(x)); },
           py::arg("point"))
      .def("level", [](const Bisection& b, ElementId e) { return b.hierarchy().level(e); }, py::arg("element"))
      .def_property_readonly("n_nodes", [](const Bisection& b) { return b.hierarchy().n_nodes(); })
      .def("memory_bytes", &Bisection::memory_bytes);
}

}  // namespace snede::bindings
