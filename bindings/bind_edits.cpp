// The local mesh edits (engine/topology: flip, split, insertion, collapse, removal, snap),
// each returning an EditResult that says whether it was done or why it was refused.
#include "bindings.hpp"
#include "mesh/mesh.hpp"
#include "topology/collapse_edge.hpp"
#include "topology/edit_result.hpp"
#include "topology/flip_edge.hpp"
#include "topology/insert_vertex.hpp"
#include "topology/remove_vertex.hpp"
#include "topology/snap_vertex.hpp"
#include "topology/split_edge.hpp"

namespace snede::bindings {

void bind_edits(py::module_& m) {
  py::class_<EditResult>(m, "EditResult", "Outcome of a local mesh edit: done, or refused (mesh unchanged) with the reason")
      .def_readonly("done", &EditResult::done)
      .def_readonly("reason", &EditResult::reason)
      .def_property_readonly("vertex", [](const EditResult& r) -> py::object {
        if (r.vertex < 0) return py::none();
        return py::int_(r.vertex);
      })
      .def("__bool__", [](const EditResult& r) { return r.done; })
      .def("__repr__", [](const EditResult& r) {
        if (!r.done) return "EditResult(refused: " + r.reason + ")";
        return r.vertex < 0 ? std::string("EditResult(done)") : "EditResult(done, vertex=" + std::to_string(r.vertex) + ")";
      });
  m.def("flip_edge", &flip_edge, py::arg("mesh"), py::arg("a"), py::arg("b"));
  m.def("is_locally_delaunay", py::overload_cast<const Mesh&, VertexId, VertexId>(&is_locally_delaunay), py::arg("mesh"), py::arg("a"), py::arg("b"));
  m.def("split_edge", &split_edge, py::arg("mesh"), py::arg("a"), py::arg("b"), py::arg("t"));
  m.def("insert_vertex",
        [](Mesh& mesh, ElementId e, const DoubleArray& weights) { return insert_vertex(mesh, e, view(weights)); },
        py::arg("mesh"), py::arg("element"), py::arg("weights"));
  m.def("collapse_edge", &collapse_edge, py::arg("mesh"), py::arg("keep"), py::arg("gone"), py::arg("t"));
  m.def("remove_vertex_by_flips", [](Mesh& mesh, VertexId v) { return remove_vertex_by_flips(mesh, v); }, py::arg("mesh"),
        py::arg("vertex"));
  m.def("snap_vertex",
        [](Mesh& mesh, VertexId v, const IndexArray& parents, const DoubleArray& weights) {
          return snap_vertex(mesh, v, parents_of(parents, weights));
        },
        py::arg("mesh"), py::arg("vertex"), py::arg("parents"), py::arg("weights"));
}

}  // namespace snede::bindings
