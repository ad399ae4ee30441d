// One binding function per engine folder; module.cpp only calls them.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <span>
#include <vector>

#include "core/solver_options.hpp"
#include "fem/material.hpp"
#include "mesh/vertex_parents.hpp"
#include "solvers/static_solver.hpp"

namespace snede::bindings {

namespace py = pybind11;

// The bases of a snede exception registered here: snede.Error (python/snede/_errors.py), then
// `builtin`, the built-in base callers catch (PyExc_ValueError...). py::register_exception
// hands its base to PyErr_NewException, which takes a tuple of bases.
inline py::tuple error_bases(PyObject* builtin) {
  return py::make_tuple(py::module_::import("snede._errors").attr("Error"), py::handle(builtin));
}

// The engine's Material from a Python material object (TypeError for anything else).
Material material_from(const py::handle& object);

void bind_core(py::module_& m);
void bind_mesh(py::module_& m);
void bind_fem(py::module_& m);
void bind_solve(py::module_& m);
void bind_dynamics(py::module_& m);
void bind_io(py::module_& m);
void bind_topology(py::module_& m);
void bind_edits(py::module_& m);
void bind_needle(py::module_& m);
void bind_cutting(py::module_& m);
void bind_planar_cutting(py::module_& m);
void bind_surface_cutting(py::module_& m);
void bind_distributed(py::module_& m);

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IndexArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

// Vertex (or element) ids from an integer array, each checked to fit a 32-bit id.
std::vector<std::int32_t> vertex_ids(const IndexArray& a);
// Barycentric parents from vertex ids and their weights (checked by VertexParents).
VertexParents parents_of(const IndexArray& vertices, const DoubleArray& weights);
inline std::span<const double> view(const DoubleArray& a) { return {a.data(), static_cast<std::size_t>(a.size())}; }

// A (rows, columns) numpy array holding a copy of `values`.
template <class T>
py::array_t<T> to_array(const std::vector<T>& values, py::ssize_t columns) {
  const py::ssize_t rows = columns ? static_cast<py::ssize_t>(values.size()) / columns : 0;
  py::array_t<T> out({rows, columns});
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

// What the 2D and the surface Delaunay cutter share: lift, cutting, the distances of §5.4 as
// resolved (a 0 given is the default from the mean edge length) and incision_edges.
template <class Cutter>
void def_delaunay_cutter_common(py::class_<Cutter>& cutter) {
  cutter.def("lift", &Cutter::lift)
      .def_property_readonly("cutting", &Cutter::cutting)
      .def_property_readonly("eps_edge", [](const Cutter& c) { return c.options().eps_edge; })
      .def_property_readonly("eps_entry", [](const Cutter& c) { return c.options().eps_entry; })
      .def_property_readonly("eps_exit", [](const Cutter& c) { return c.options().eps_exit; })
      .def("incision_edges", [](const Cutter& c) { return to_array(c.incision_edges(), 2); });
}

}  // namespace snede::bindings
