#include "bindings.hpp"
#include "petsc4py_interop.hpp"
#include "core/error.hpp"
#include "mesh/mesh.hpp"
#include "mesh/traversal.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {
namespace {

Mesh make_mesh(const DoubleArray& points, const IndexArray& cells) {
  if (points.ndim() != 2 || cells.ndim() != 2) throw std::invalid_argument("points and cells must be 2-D arrays");
  const int space_dim = static_cast<int>(points.shape(1));
  const int cell_dim = static_cast<int>(cells.shape(1)) - 1;
  std::vector<double> p(points.data(), points.data() + points.size());
  return Mesh(cell_dim, space_dim, std::move(p), std::span<const std::int64_t>(cells.data(), cells.size()));
}

py::array_t<bool> live_vertices(const Mesh& mesh) {
  py::array_t<bool> live(mesh.n_points());
  for (VertexId v = 0; v < mesh.n_points(); ++v) live.mutable_at(v) = mesh.is_vertex(v);
  return live;
}

py::dict quality_arrays(const Mesh& mesh) {
  const auto q = mesh.quality();
  py::array_t<double> volume(q.size()), aspect(q.size()), min_dihedral(q.size()), max_dihedral(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    volume.mutable_at(i) = q[i].volume;
    aspect.mutable_at(i) = q[i].aspect_ratio;
    min_dihedral.mutable_at(i) = q[i].min_dihedral;
    max_dihedral.mutable_at(i) = q[i].max_dihedral;
  }
  py::dict out;
  out["volume"] = volume;
  out["aspect_ratio"] = aspect;
  out["min_dihedral"] = min_dihedral;
  out["max_dihedral"] = max_dihedral;
  return out;
}

// The points as a sequential PETSc Vec of block size dim, handed to petsc4py.
py::object points_vec(const Mesh& mesh) {
  Vec v = nullptr;
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(mesh.points().size()), &v));
  SNEDE_PETSC(VecSetBlockSize(v, mesh.dim()));
  PetscScalar* data = nullptr;
  SNEDE_PETSC(VecGetArray(v, &data));
  std::copy(mesh.points().begin(), mesh.points().end(), data);
  SNEDE_PETSC(VecRestoreArray(v, &data));
  py::object wrapped = to_petsc4py(v);
  SNEDE_PETSC(VecDestroy(&v));
  return wrapped;
}

// The oriented vertices of a live element (its row of `cells`).
std::vector<VertexId> element_vertices(const Mesh& mesh, ElementId e) {
  if (!mesh.connectivity().is_element(e)) throw std::invalid_argument("element " + std::to_string(e) + " does not exist");
  const auto oriented = mesh.connectivity().element(e).simplex.oriented_vertices();
  return {oriented.begin(), oriented.begin() + mesh.cell_dim() + 1};
}

std::vector<ElementId> star_of(const Mesh& mesh, VertexId v) { return vertex_star(mesh.connectivity(), v); }

py::tuple components_of(const Mesh& mesh) {
  auto [label, n] = connected_components(mesh.connectivity());
  std::vector<int> live;
  for (ElementId e : mesh.cell_ids()) live.push_back(label[e]);
  return py::make_tuple(n, py::array_t<int>(live.size(), live.data()));
}

}  // namespace

VertexParents parents_of(const IndexArray& vertices, const DoubleArray& weights) {
  const std::vector<VertexId> ids = vertex_ids(vertices);
  return VertexParents::barycentric(ids, view(weights));
}

std::vector<std::int32_t> vertex_ids(const IndexArray& a) {
  std::vector<std::int32_t> ids(a.size());
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    const std::int64_t v = a.data()[i];
    if (v < 0 || v > std::numeric_limits<std::int32_t>::max())
      throw std::invalid_argument("id " + std::to_string(v) + " is out of range");
    ids[i] = static_cast<std::int32_t>(v);
  }
  return ids;
}

void bind_mesh(py::module_& m) {
  py::register_exception<InvalidMesh>(m, "InvalidMesh", error_bases(PyExc_ValueError));
  py::class_<Mesh>(m, "Mesh")
      .def(py::init(&make_mesh), py::arg("points"), py::arg("cells"))
      .def_property_readonly("dim", &Mesh::dim)
      .def_property_readonly("cell_dim", &Mesh::cell_dim)
      .def_property_readonly("space_dim", &Mesh::space_dim)
      .def_property_readonly("n_live_points", &Mesh::n_live_points)
      .def_property_readonly("live_vertices", &live_vertices)
      .def_property_readonly("n_points", &Mesh::n_points)
      .def_property_readonly("n_cells", &Mesh::n_cells)
      .def_property_readonly("n_reoriented", &Mesh::n_reoriented)
      .def_property_readonly("points", [](const Mesh& mesh) { return to_array(mesh.points(), mesh.dim()); })
      .def_property_readonly("cells", [](const Mesh& mesh) { return to_array(mesh.cells(), mesh.cell_dim() + 1); })
      .def_property_readonly("cell_ids", &Mesh::cell_ids)
      .def_property_readonly("revision", [](const Mesh& mesh) { return mesh.connectivity().revision(); })
      .def("boundary_faces", [](const Mesh& mesh) { return to_array(mesh.boundary_faces(), mesh.cell_dim()); })
      .def("quality", &quality_arrays)
      .def("validate", &Mesh::validate)
      .def("points_vec", &points_vec)
      .def("star", &star_of, py::arg("vertex"))
      .def("connected_components", &components_of)
      .def("add_vertex", [](Mesh& mesh, const IndexArray& v, const DoubleArray& w) { return mesh.add_vertex(parents_of(v, w)); },
           py::arg("parents"), py::arg("weights"))
      // The live vertices added by an edit (those with recorded parents), ascending.
      .def("rows_with_parents", [](const Mesh& mesh) {
             std::vector<std::int64_t> rows;
             for (VertexId v = 0; v < mesh.n_points(); ++v)
               if (mesh.is_vertex(v) && mesh.parents(v).count() > 0) rows.push_back(v);
             return to_array(rows, 1);
           })
      .def("move_vertex", [](Mesh& mesh, VertexId v, const IndexArray& p, const DoubleArray& w) {
             mesh.move_vertex(v, parents_of(p, w));
           }, py::arg("vertex"), py::arg("parents"), py::arg("weights"))
      .def("move_vertex_to", [](Mesh& mesh, VertexId v, const DoubleArray& x) { mesh.move_vertex(v, view(x)); },
           py::arg("vertex"), py::arg("point"))
      .def("remove_vertex", &Mesh::remove_vertex, py::arg("vertex"))
      .def("element_vertices", &element_vertices, py::arg("element"))
      .def("begin_batch", [](Mesh& mesh) { mesh.connectivity().begin_batch(); })
      .def("end_batch", [](Mesh& mesh) { mesh.connectivity().end_batch(); })
      .def("memory_bytes", [](const Mesh& mesh) {
        return mesh.connectivity().memory_bytes() + mesh.points().capacity() * sizeof(double);
      });
}

}  // namespace snede::bindings
