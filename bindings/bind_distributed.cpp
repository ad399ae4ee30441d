#include "bindings.hpp"
#include "core/rank_agreement.hpp"
#include "mesh/distributed_mesh.hpp"
#include "solvers/dynamic_relaxation.hpp"
#include "problem/distributed_static.hpp"
#include "problem/model.hpp"
#include "topology/rank_refinement.hpp"

#include <pybind11/stl.h>

#include <optional>
#include <string_view>

namespace snede::bindings {

void bind_distributed(py::module_& m) {
  py::class_<DistributedMesh>(m, "DistributedMesh")
      .def_property_readonly(
          "local", [](DistributedMesh& d) -> Mesh& { return *d.local; }, py::return_value_policy::reference_internal)
      .def_property_readonly("global_vertex", [](const DistributedMesh& d) { return to_array(d.global_vertex, 1); })
      .def_property_readonly("owned", [](const DistributedMesh& d) { return to_array(d.owned, 1); })
      .def_property_readonly("global_number", [](const DistributedMesh& d) { return to_array(d.global_number, 1); })
      // Gives the vertices other global ids (a series written on ranks: its rows' serial ids),
      // one per local vertex, each in 0..n_global_vertices − 1.
      .def("renumber_vertices",
           [](DistributedMesh& d, const IndexArray& ids) {
             if (ids.size() != static_cast<py::ssize_t>(d.global_vertex.size()))
               throw std::invalid_argument("renumber_vertices: " + std::to_string(ids.size()) + " ids for " +
                                           std::to_string(d.global_vertex.size()) + " local vertices");
             for (py::ssize_t k = 0; k < ids.size(); ++k)
               if (ids.data()[k] < 0 || ids.data()[k] >= d.n_global_vertices)
                 throw std::invalid_argument("renumber_vertices: id " + std::to_string(ids.data()[k]) +
                                             " is outside 0.." + std::to_string(d.n_global_vertices - 1));
             d.global_vertex.assign(ids.data(), ids.data() + ids.size());
           },
           py::arg("ids"))
      .def_readonly("n_global_vertices", &DistributedMesh::n_global_vertices)
      .def_readonly("n_global_cells", &DistributedMesh::n_global_cells);
  // `comm` is the communicator's Fortran handle (mpi4py's Comm.py2f()).
  m.def(
      "distribute_mesh",
      [](std::int64_t comm, const Mesh* serial) {
        return distribute_mesh(MPI_Comm_f2c(static_cast<MPI_Fint>(comm)), serial);
      },
      py::arg("comm"), py::arg("serial").none(true));
  // This rank's part of a mesh: cells by global vertex ids, ((cell_dim + 1) per row), and the
  // coordinates of this rank's range of vertices ((n, space_dim)).
  m.def(
      "distribute_cells",
      [](std::int64_t comm, int cell_dim, const IndexArray& cells, const DoubleArray& coordinates, bool keep_as_given) {
        RankCells part;
        part.cell_dim = cell_dim;
        part.space_dim = coordinates.ndim() == 2 ? static_cast<int>(coordinates.shape(1)) : 0;
        part.cells.assign(cells.data(), cells.data() + cells.size());
        part.coordinates.assign(coordinates.data(), coordinates.data() + coordinates.size());
        py::gil_scoped_release released;
        return distribute_cells(MPI_Comm_f2c(static_cast<MPI_Fint>(comm)), std::move(part), keep_as_given);
      },
      py::arg("comm"), py::arg("cell_dim"), py::arg("cells"), py::arg("coordinates"), py::arg("keep_as_given") = false);
  // Conforming bisection on ranks (collective). Each edit returns (field as (n, width), (n_new, 3)
  // new vertices this rank numbered with their parents, cells split over all ranks, the
  // rebalanced part or None, and its labels as (rule, (n_cells, cell_dim + 2))).
  const auto report = [](RankRefinementReport r, int width) {
    const auto corners = static_cast<py::ssize_t>(r.rebalanced ? r.rebalanced->local->cell_dim() + 2 : 1);
    py::object rebalanced = py::none();
    if (r.rebalanced) rebalanced = py::cast(std::move(*r.rebalanced));
    return py::make_tuple(to_array(r.field, width), to_array(r.new_vertices, 3), r.n_split, rebalanced,
                          static_cast<int>(r.labels.rule), to_array(r.labels.cells, corners));
  };
  const auto view = [](const DoubleArray& a) { return std::span<const double>(a.data(), static_cast<std::size_t>(a.size())); };
  py::class_<PartRefinement>(m, "PartRefinement")
      .def(py::init([](const DistributedMesh& part, const py::object& labels) {
             if (labels.is_none()) return std::make_unique<PartRefinement>(part, nullptr);
             const auto [rule, cells] = labels.cast<std::pair<int, IndexArray>>();
             const PartLabels given{.rule = static_cast<BisectionRule>(rule),
                                    .cells = std::vector<std::int64_t>(cells.data(), cells.data() + cells.size())};
             return std::make_unique<PartRefinement>(part, &given);
           }),
           py::arg("part"), py::arg("labels").none(true))
      .def_property_readonly(
          "part", [](PartRefinement& r) -> DistributedMesh& { return r.part(); }, py::return_value_policy::reference_internal)
      .def_property_readonly("original_vertex", [](const PartRefinement& r) { return to_array(r.original_vertex(), 1); })
      .def_property_readonly("spent", &PartRefinement::spent)
      .def(
          "refine_uniform",
          [report, view](PartRefinement& r, int levels, const DoubleArray& field, int width) {
            py::gil_scoped_release released;
            RankRefinementReport done = r.refine_uniform(levels, view(field), width);
            py::gil_scoped_acquire acquired;
            return report(std::move(done), width);
          },
          py::arg("levels"), py::arg("field"), py::arg("width"))
      .def(
          "refine_around",
          [report, view](PartRefinement& r, const DoubleArray& x, double h, const DoubleArray& field, int width) {
            py::gil_scoped_release released;
            RankRefinementReport done = r.refine_around(view(x), h, view(field), width);
            py::gil_scoped_acquire acquired;
            return report(std::move(done), width);
          },
          py::arg("x"), py::arg("h"), py::arg("field"), py::arg("width"))
      .def(
          "refine_near_segment",
          [report, view](PartRefinement& r, const DoubleArray& a, const DoubleArray& b, double h, double radius,
                         const DoubleArray& field, int width) {
            py::gil_scoped_release released;
            RankRefinementReport done = r.refine_near_segment(view(a), view(b), h, radius, view(field), width);
            py::gil_scoped_acquire acquired;
            return report(std::move(done), width);
          },
          py::arg("a"), py::arg("b"), py::arg("h"), py::arg("radius"), py::arg("field"), py::arg("width"));
  // RankAgreement for Python's collective calls: `inputs` are (name, the input's bytes) pairs,
  // the same names in the same order on every rank.
  m.def(
      "require_same_on_every_rank",
      [](std::int64_t comm, const std::string& caller, const std::vector<std::pair<std::string, py::bytes>>& inputs) {
        RankAgreement agreement(caller);
        for (const auto& [name, bytes] : inputs) {
          const std::string_view view(bytes);
          agreement.input(name, std::span<const char>(view.data(), view.size()));
        }
        agreement.require(MPI_Comm_f2c(static_cast<MPI_Fint>(comm)));
      },
      py::arg("comm"), py::arg("caller"), py::arg("inputs"));

  // A serial Model's sliding vertices with their lines' unit directions and anchors (each
  // (n, dim)): what a distributed solve takes over from Body.slide.
  m.def(
      "sliding_lines",
      [](const Model& model) {
        const Constraints& c = model.constraints();
        const int dim = model.dim();
        std::vector<std::int64_t> sliding;
        std::vector<double> directions, anchors;
        for (VertexId v = 0; v < c.n_points(); ++v) {
          if (c[v].kind != ConstraintKind::slide) continue;
          sliding.push_back(v);
          directions.insert(directions.end(), c[v].direction.begin(), c[v].direction.begin() + dim);
          anchors.insert(anchors.end(), c[v].anchor.begin(), c[v].anchor.begin() + dim);
        }
        return py::make_tuple(to_array(sliding, 1), to_array(directions, dim), to_array(anchors, dim));
      },
      py::arg("model"));

  py::class_<DistributedStatic, Problem>(m, "DistributedStatic")
      .def(py::init([](DistributedMesh& part, const py::handle& material, double density, double thickness,
                       std::vector<std::int64_t> fixed, std::vector<double> fixed_values, std::vector<std::int64_t> sliding,
                       std::vector<double> sliding_directions, std::vector<double> sliding_anchors,
                       std::vector<std::int64_t> loaded, std::vector<double> forces, std::vector<double> gravity) {
             return std::make_unique<DistributedStatic>(
                 part, material_from(material), density, thickness,
                 DistributedConditions{std::move(fixed), std::move(fixed_values), std::move(sliding),
                                       std::move(sliding_directions), std::move(sliding_anchors), std::move(loaded),
                                       std::move(forces), std::move(gravity)});
           }),
           py::arg("part"), py::arg("material"), py::arg("density"), py::arg("thickness"), py::arg("fixed"), py::arg("fixed_values"),
           py::arg("sliding"), py::arg("sliding_directions"), py::arg("sliding_anchors"), py::arg("loaded"), py::arg("forces"), py::arg("gravity"), py::keep_alive<1, 2>())
      .def(
          "set_displacement",
          [](DistributedStatic& s, py::array_t<double, py::array::c_style | py::array::forcecast> serial) {
            s.set_displacement(std::span<const double>(serial.data(), static_cast<std::size_t>(serial.size())));
          },
          py::arg("serial_displacement"))
      .def(
          "set_local_displacement",
          [](DistributedStatic& s, py::array_t<double, py::array::c_style | py::array::forcecast> local) {
            s.set_local_displacement(std::span<const double>(local.data(), static_cast<std::size_t>(local.size())));
          },
          py::arg("local_displacement"))
      .def(
          "inverted_local_elements",
          [](const DistributedStatic& s, py::array_t<double, py::array::c_style | py::array::forcecast> local) {
            return to_array(s.inverted_local_elements(
                                std::span<const double>(local.data(), static_cast<std::size_t>(local.size()))),
                            1);
          },
          py::arg("local_displacement"))
      .def("require_held", &DistributedStatic::require_held,
           "Collective: ValueError on every rank when some piece of the body (on any ranks) is not held "
           "(the serial Body's check, problem/rank_piece_holding.hpp).")
      // (each local cell's piece over all ranks, in cell_ids order; how many pieces; the loose ones).
      .def("pieces", [](const DistributedStatic& s) {
             const RankPieces pieces = s.pieces();
             std::vector<std::int64_t> labels(pieces.cell_piece.begin(), pieces.cell_piece.end()), loose;
             for (const LoosePiece& piece : pieces.loose) loose.push_back(piece.piece);
             return py::make_tuple(to_array(labels, 1), pieces.n_pieces, to_array(loose, 1));
           })
      .def("energy", [](DistributedStatic& s) { return s.energy(); })
      .def("local_displacement", [](DistributedStatic& s) { return to_array(s.local_displacement(), 1); });
}

}  // namespace snede::bindings
