#include "bindings.hpp"
#include "mesh/mesh.hpp"
#include "topology/bisection.hpp"
#include "topology/dissect.hpp"
#include "topology/refine_around.hpp"
#include "topology/refine_near_segment.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {
namespace {


py::array_t<VertexId> dissect_faces(Mesh& mesh, const IndexArray& faces) {
  std::vector<VertexId> split;
  for (const SplitVertex& s : dissect(mesh, vertex_ids(faces))) {
    split.push_back(s.original);
    split.push_back(s.copy);
  }
  return to_array(split, 2);
}

}  // namespace

void bind_topology(py::module_& m) {
  m.def("dissect", &dissect_faces, py::arg("mesh"), py::arg("faces"),
        "§7.3 dissect along interior faces ((n, cell_dim) vertex ids); returns (original, copy) pairs");
  py::class_<Bisection>(m, "Bisection")
      .def(py::init<Mesh&>(), py::arg("mesh"), py::keep_alive<1, 2>())
      .def("refine_uniform", &Bisection::refine_uniform, py::arg("levels"))
      .def("refine_near_segment",
           [](Bisection& b, const DoubleArray& a, const DoubleArray& c, double h, double radius) {
             return refine_near_segment(b, view(a), view(c), h, radius);
           },
           py::arg("a"), py::arg("b"), py::arg("h"), py::arg("radius"))
      .def("refine_around",
           [](Bisection& b, const DoubleArray& x, double h) { return refine_around(b, view(x), h); },
           py::arg("point"), py::arg("h"))
      .def("bisect", &Bisection::bisect, py::arg("element"))
      .def("locate_all", [](const Bisection& b, const DoubleArray& x) { return b.hierarchy().locate_all(view(x)); },
           py::arg("point"))
      .def("level", [](const Bisection& b, ElementId e) { return b.hierarchy().level(e); }, py::arg("element"))
      .def_property_readonly("n_nodes", [](const Bisection& b) { return b.hierarchy().n_nodes(); })
      .def_property_readonly("n_forced_splits", &Bisection::n_forced_splits)
      .def_property_readonly(
          "rule",
          [](const Bisection& b) {
            return b.hierarchy().rule() == BisectionRule::longest_edge ? "longest_edge" : "newest_vertex";
          },
          "3D labelling rule: 'newest_vertex' (Maubach, the Kuhn box) or 'longest_edge' (any other mesh)")
      .def("memory_bytes", &Bisection::memory_bytes);
}

}  // namespace snede::bindings
