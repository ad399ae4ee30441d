#include "bindings.hpp"
#include "record_binding.hpp"
#include "cutting/tetrahedral_cutter.hpp"
#include "cut_model_adapter.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {

// The engine's CutterOptions as a Python record (snede.TetrahedralCutterOptions): its fields by
// name, the degeneracy thresholds flattened; the defaults are the engine's. The cutter checks
// the thresholds when it is made.
struct TetrahedralCutterOptions : CutterOptions {
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("snap", &CutterOptions::snap);
    visit("remove_degeneracies", &CutterOptions::remove_degeneracies);
    visit("min_aspect_ratio", [](auto& options) -> auto& { return options.degeneracy.min_aspect_ratio; });
    visit("large_angle", [](auto& options) -> auto& { return options.degeneracy.large_angle; });
    visit("fix_free_pieces", &CutterOptions::fix_free_pieces);
    visit("max_fragment_elements", &CutterOptions::max_fragment_elements);
  }
};

void bind_cutting(py::module_& m) {
  bind_record<CutResult>(
      m, "CutResult",
      "What one ``move`` or ``cut_triangle`` did.\n\n"
      "``faces_dissected`` counts selected faces the dissection opened; a face whose vertices' stars do not\n"
      "split yet (Figure 7.7) stays joined and is cut again with the next sweep. ``degenerate_found`` counts\n"
      "the flat elements (aspect ratio below the threshold) around the cut before removal,\n"
      "``degenerate_shapes`` them as (needles, spindles, slivers, caps); ``elements_cut_free`` the\n"
      "incollapsible ones that were cut free and removed. ``components`` is the number of pieces of the body\n"
      "afterwards. On a sweep that separates a piece, ``free_pieces`` counts the pieces with no constraint\n"
      "and ``pieces_fixed`` those of them fixed on one face (``fix_free_pieces``). ``fragments_removed``\n"
      "counts the separated pieces no bigger than ``max_fragment_elements`` mean elements that were removed,\n"
      "``fragment_elements`` the elements they had; ``piece_elements`` the elements of each piece, largest\n"
      "first, after a sweep that separated one (empty otherwise). ``piece_search`` is the number of elements\n"
      "the local search for separated pieces visited (it stays near the cut unless a piece separates).\n"
      "``a + b``: both reports together (counts and times add up; ``components`` is ``b``'s unless it swept\n"
      "nothing), as ``move`` combines its halves.")
      .def("__str__", [](const CutResult& r) { return summary(r); });
  m.attr("CutReport") = m.attr("CutResult");  // its name before issue 51: records pickled then load

  bind_record<TetrahedralCutterOptions>(
      m, "TetrahedralCutterOptions",
      "A TetrahedralCutter's settings (snede.TetrahedralCutter documents each); the engine's CutterOptions,\n"
      "its degeneracy thresholds flattened. The cutter refuses thresholds out of range when it is made.");

  py::class_<TetrahedralCutter>(m, "TetrahedralCutter")
      .def(py::init([](Mesh& mesh, Model* model, const TetrahedralCutterOptions& options) {
             return std::make_unique<TetrahedralCutter>(mesh, cut_body_of(model, mesh, "TetrahedralCutter"), options);
           }),
           py::arg("mesh"), py::arg("model"), py::arg("options"), py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      // Without the GIL (other Python threads run), as the solves.
      .def("cut_triangle", [](TetrahedralCutter& c, const DoubleArray& corners) { return c.cut_triangle(view(corners)); },
           py::arg("corners"), py::call_guard<py::gil_scoped_release>())
      .def("move", [](TetrahedralCutter& c, const DoubleArray& scalpel) { return c.move(view(scalpel)); },
           py::arg("scalpel"), py::call_guard<py::gil_scoped_release>())
      .def("lift", &TetrahedralCutter::lift)
      .def_property_readonly("placed", &TetrahedralCutter::placed)
      .def("incision_faces", [](const TetrahedralCutter& c) { return to_array(c.incision_faces(), 3); });
}

}  // namespace snede::bindings
