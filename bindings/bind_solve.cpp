#include "bindings.hpp"
#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "petsc4py_interop.hpp"
#include "record_binding.hpp"
#include "problem/model.hpp"
#include "problem/piece_holding.hpp"
#include "problem/problem.hpp"
#include "solvers/solve_result.hpp"
#include "solvers/static_solver.hpp"
#include "problem/tangent_assembly.hpp"
#include "topology/bisection.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {
namespace {

py::array_t<double> vec_to_array(Vec v, int dim) { return to_array(vec_values(v), dim); }

void array_to_vec(const DoubleArray& a, Vec v) { set_vec_values(v, view(a)); }

py::array_t<double> reactions_of(Model& model) {
  VecHandle R;
  SNEDE_PETSC(VecDuplicate(model.displacement(), R.out()));
  model.reaction_forces(model.displacement(), R);
  return vec_to_array(R, model.dim());
}

// The shell at u: a petsc4py Mat sharing the model's (it applies J at the last point set).
py::object tangent_operator_at(Model& model, const DoubleArray& u) {
  set_vec_values(model.linearization_point(), view(u));
  return to_petsc4py(model.tangent());
}

// A new assembled J at u, owned by the petsc4py Mat returned.
py::object assembled_tangent_at(Model& model, const DoubleArray& u, const std::string& format) {
  if (format != "aij" && format != "baij")
    throw std::invalid_argument("format must be 'aij' or 'baij', got '" + format + "'");
  VecHandle x;
  SNEDE_PETSC(VecDuplicate(model.displacement(), x.out()));
  set_vec_values(x, view(u));
  AssembledTangent tangent(model, format == "baij" ? MatrixFormat::baij : MatrixFormat::aij);
  tangent.assemble(model, x);
  return to_petsc4py(tangent.mat());  // petsc4py takes a reference; the handle drops ours
}

}  // namespace

void bind_solve(py::module_& m) {
  bind_record<SolveResult>(
      m, "SolveResult",
      "``converged`` is False whenever the final state is not trustworthy: PETSc reported divergence,\n"
      "the iteration limit was hit, or the state holds NaN/Inf or an inverted element of a material\n"
      "that forbids inversion. ``reason`` is PETSc's converged reason (e.g. ``CONVERGED_FNORM_RELATIVE``,\n"
      "``DIVERGED_LINE_SEARCH``) or snede's own (``DIVERGED_INVERTED_ELEMENTS``, ``DIVERGED_NONFINITE_STATE``,\n"
      "``DIVERGED_BLOW_UP``). ``seconds`` is the solve's wall time; ``flops`` counts the floating-point\n"
      "operations PETSc logged during the solve on this rank, in FLOP (``str(result)`` shows them in\n"
      "MFLOP, 10⁶ FLOP).")
      .def("__str__", &summary);
  py::class_<Model>(m, "Model")
      .def(py::init<ElasticBody&>(), py::arg("body"), py::keep_alive<1, 2>())
      .def("fix", [](Model& s, const IndexArray& v, const DoubleArray& values) { s.fix(vertex_ids(v), view(values)); })
      .def("slide", [](Model& s, const IndexArray& v, const DoubleArray& t) { s.slide(vertex_ids(v), view(t)); })
      .def("release", [](Model& s, const IndexArray& v) { s.constraints().release(vertex_ids(v)); })
      .def("set_gravity", [](Model& s, const DoubleArray& g) { s.set_gravity(view(g)); })
      .def("clear_gravity", &Model::clear_gravity)
      .def("add_nodal_force", [](Model& s, const std::string& channel, const IndexArray& v, const DoubleArray& f) {
             s.add_nodal_force(channel, vertex_ids(v), view(f));
           }, py::arg("channel"), py::arg("vertices"), py::arg("forces"))
      .def("set_nodal_forces", [](Model& s, const std::string& channel, const IndexArray& v, const DoubleArray& f) {
             s.set_nodal_forces(channel, vertex_ids(v), view(f));
           }, py::arg("channel"), py::arg("vertices"), py::arg("forces"))
      .def("clear_channel", &Model::clear_channel, py::arg("channel"))
      .def("clear_loads", &Model::clear_loads)
      .def_property_readonly("load_channels", &Model::load_channels)
      .def("channel_forces", [](const Model& s, const std::string& c) { return to_array(s.channel_forces(c), s.dim()); })
      .def_property_readonly("has_gravity", [](const Model& s) { return s.has_gravity(); })
      .def("external_forces", [](Model& s) { return to_array(s.external_forces(), s.dim()); })
      .def("reaction_forces", &reactions_of)
      .def_property_readonly("n_constrained", [](const Model& s) { return s.constraints().n_constrained(); })
      // (fixed vertices, their anchors (n, dim), sliding vertices): what a distributed solve
      // takes over from the serial body.
      .def("constraint_table", [](const Model& s) {
             const Constraints& c = s.constraints();
             std::vector<std::int64_t> fixed, sliding;
             std::vector<double> anchors;
             for (VertexId v = 0; v < c.n_points(); ++v) {
               if (c[v].kind == ConstraintKind::slide) sliding.push_back(v);
               if (c[v].kind != ConstraintKind::fixed) continue;
               fixed.push_back(v);
               anchors.insert(anchors.end(), c[v].anchor.begin(), c[v].anchor.begin() + s.dim());
             }
             return py::make_tuple(to_array(fixed, 1), to_array(anchors, s.dim()), to_array(sliding, 1));
           })
      // (sliding vertices, their lines' directions (n, dim), their anchors (n, dim)).
      .def("sliding_table", [](const Model& s) {
             const Constraints& c = s.constraints();
             std::vector<std::int64_t> sliding;
             std::vector<double> directions, anchors;
             for (VertexId v = 0; v < c.n_points(); ++v) {
               if (c[v].kind != ConstraintKind::slide) continue;
               sliding.push_back(v);
               directions.insert(directions.end(), c[v].direction.begin(), c[v].direction.begin() + s.dim());
               anchors.insert(anchors.end(), c[v].anchor.begin(), c[v].anchor.begin() + s.dim());
             }
             return py::make_tuple(to_array(sliding, 1), to_array(directions, s.dim()), to_array(anchors, s.dim()));
           })
      // The corners of one cell of each piece the constraints do not hold, (n_pieces, cell_dim + 1).
      .def("loose_piece_cells", [](Model& s) {
             const Mesh& mesh = s.body().mesh();
             std::vector<std::int64_t> corners;
             for (const LoosePiece& piece : PieceHolding(mesh).loose_pieces(s.constraints())) {
               const auto cell = mesh.connectivity().element(piece.first_cell).simplex.vertices();
               corners.insert(corners.end(), cell.begin(), cell.end());
             }
             return to_array(corners, mesh.cell_dim() + 1);
           })
      .def("require_held", [](Model& s) { PieceHolding(s.body().mesh()).require_held(s.constraints()); })
      .def_property_readonly("generation", &Model::generation)
      .def_property("displacement", [](const Model& s) { return vec_to_array(s.displacement(), s.dim()); },
                    [](Model& s, const DoubleArray& u) { array_to_vec(u, s.displacement()); })
      .def_property_readonly("displacement_vec", [](const Model& s) { return to_petsc4py(s.displacement()); })
      .def_property_readonly("tangent_mat", [](const Model& s) { return to_petsc4py(s.tangent()); })
      .def("tangent_operator", &tangent_operator_at, py::arg("u"))
      .def("assemble_tangent", &assembled_tangent_at, py::arg("u"), py::arg("format"));

  py::class_<Problem>(m, "Problem", "A static problem on a communicator, which the solvers drive (problem.hpp).");

  bind_record<StaticOptions>(m, "StaticOptions",
                             "A static solver's settings (snede.StaticSolver documents each); the engine's struct.\n"
                             "``method`` and ``criterion`` are their names (``\"ncg\"``, ``\"6.9\"``).");
  // The names `method` takes, from the engine's table (static_options.hpp): Python lists them
  // nowhere else.
  py::tuple methods(static_method_names.size());
  for (std::size_t i = 0; i < static_method_names.size(); ++i) methods[i] = py::str(std::string(static_method_names[i].second));
  m.attr("static_methods") = methods;
  m.def("distributed_solve_options", &distributed_solve_options,
        "The settings of DistributedStatic.solve unless told otherwise (a StaticOptions).");

  py::class_<StaticSolver>(m, "StaticSolver")
      .def(py::init([](Model& model, StaticOptions options, const Bisection* bisection) {
             return std::make_unique<StaticSolver>(model, std::move(options),
                                                   bisection ? &bisection->hierarchy() : nullptr);
           }),
           py::arg("model"), py::arg("options"), py::arg("bisection"), py::keep_alive<1, 2>(), py::keep_alive<1, 4>())
      // A distributed problem on its communicator: collective.
      .def(py::init([](DistributedStatic& problem, StaticOptions options) {
             return std::make_unique<StaticSolver>(problem, std::move(options));
           }),
           py::arg("problem"), py::arg("options"), py::keep_alive<1, 2>())
      .def_property_readonly("preconditioner", &StaticSolver::preconditioner)
      .def_property_readonly("multigrid_levels", &StaticSolver::multigrid_levels)
      .def_property_readonly("multigrid_unknowns", &StaticSolver::multigrid_unknowns)
      .def_property_readonly("multigrid_source", &StaticSolver::multigrid_source)
      .def_property_readonly("follow_seconds", &StaticSolver::follow_seconds)
      .def_property_readonly("preconditioner_fills", &StaticSolver::preconditioner_fills)
      .def_property_readonly("multigrid_builds", &StaticSolver::multigrid_builds)
      .def_property_readonly("multigrid_edits", &StaticSolver::multigrid_edits)
      .def_property_readonly("sparsity_builds", &StaticSolver::sparsity_builds)
      .def_property_readonly("sparsity_edits", &StaticSolver::sparsity_edits)
      .def_property_readonly("tangent_assemblies", &StaticSolver::tangent_assemblies)
      .def_property_readonly("piece_labellings", &StaticSolver::piece_labellings)
      // Without the GIL (other Python threads run); the interrupt check and petsc4py's callbacks take it.
      .def("solve", &StaticSolver::solve, py::call_guard<py::gil_scoped_release>())
      .def(
          "use_bisection",
          [](StaticSolver& solver, const Bisection* bisection) {
            solver.use_hierarchy(bisection ? &bisection->hierarchy() : nullptr);
          },
          py::arg("bisection"), py::keep_alive<1, 2>())
      .def_property_readonly("ksp", [](const StaticSolver& s) { return to_petsc4py(s.ksp()); })
      .def_property_readonly("snes", [](const StaticSolver& s) {
        return s.snes() ? to_petsc4py(s.snes()) : py::object(py::none());
      });
}

}  // namespace snede::bindings
