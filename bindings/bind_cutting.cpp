#include "bindings.hpp"
#include "cutting/tetrahedral_cutter.hpp"
#include "solve/cut_model_adapter.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {
namespace {

std::unique_ptr<TetrahedralCutter> make_cutter(Mesh& mesh, Model* model, bool snap, bool remove_degeneracies,
                                               double min_aspect_ratio, double large_angle, bool fix_free_pieces,
                                               int max_fragment_elements) {
  CutterOptions options;
  options.snap = snap;
  options.remove_degeneracies = remove_degeneracies;
  options.degeneracy.min_aspect_ratio = min_aspect_ratio;
  options.degeneracy.large_angle = large_angle;
  options.fix_free_pieces = fix_free_pieces;
  options.max_fragment_elements = max_fragment_elements;
  return std::make_unique<TetrahedralCutter>(mesh, cut_body_of(model, mesh, "TetrahedralCutter"), options);
}

}  // namespace

void bind_cutting(py::module_& m) {
  py::class_<CutReport>(m, "CutReport")
      .def(py::init<>())
      .def("add", &CutReport::add, py::arg("other"))
      .def_readwrite("sweeps", &CutReport::sweeps)
      .def_readwrite("faces_selected", &CutReport::faces_selected)
      .def_readwrite("faces_dissected", &CutReport::faces_dissected)
      .def_readwrite("vertices_split", &CutReport::vertices_split)
      .def_readwrite("vertices_snapped", &CutReport::vertices_snapped)
      .def_readwrite("snaps_refused", &CutReport::snaps_refused)
      .def_readwrite("degenerate_found", &CutReport::degenerate_found)
      .def_readwrite("degenerate_shapes", &CutReport::degenerate_shapes)
      .def_readwrite("edges_collapsed", &CutReport::edges_collapsed)
      .def_readwrite("edges_split", &CutReport::edges_split)
      .def_readwrite("faces_split", &CutReport::faces_split)
      .def_readwrite("elements_cut_free", &CutReport::elements_cut_free)
      .def_readwrite("components", &CutReport::components)
      .def_readwrite("free_pieces", &CutReport::free_pieces)
      .def_readwrite("pieces_fixed", &CutReport::pieces_fixed)
      .def_readwrite("fragments_removed", &CutReport::fragments_removed)
      .def_readwrite("fragment_elements", &CutReport::fragment_elements)
      .def_readwrite("piece_elements", &CutReport::piece_elements)
      .def_readwrite("piece_search", &CutReport::piece_search)
      .def_readwrite("seconds", &CutReport::seconds);

  py::class_<TetrahedralCutter>(m, "TetrahedralCutter")
      .def(py::init(&make_cutter), py::arg("mesh"), py::arg("model"), py::arg("snap"), py::arg("remove_degeneracies"),
           py::arg("min_aspect_ratio"), py::arg("large_angle"), py::arg("fix_free_pieces"), py::arg("max_fragment_elements"),
           py::keep_alive<1, 2>(),
           py::keep_alive<1, 3>())
      .def("cut_triangle", [](TetrahedralCutter& c, const DoubleArray& corners) { return c.cut_triangle(view(corners)); },
           py::arg("corners"))
      .def("move", [](TetrahedralCutter& c, const DoubleArray& scalpel) { return c.move(view(scalpel)); },
           py::arg("scalpel"))
      .def("lift", &TetrahedralCutter::lift)
      .def_property_readonly("placed", &TetrahedralCutter::placed)
      .def("incision_faces", [](const TetrahedralCutter& c) { return to_array(c.incision_faces(), 3); });
}

}  // namespace snede::bindings
