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
      .def("incision_faces", [](const TetrahedralCutter& c) { return to_array(c.incision_faces(), 3); })
      // The cutter's memory (tetrahedral_cutter.hpp) as a dict of arrays, faces and tetrahedra as
      // positively ordered vertex rows; restore() takes the same dict in another numbering.
      .def("memory", [](const TetrahedralCutter& c) {
             const CutterMemory memory = c.memory();
             const auto rows = [](const std::vector<Simplex>& simplexes, int corners) {
               std::vector<std::int64_t> flat;
               for (const Simplex& sigma : simplexes) {
                 const auto v = sigma.oriented_vertices();
                 flat.insert(flat.end(), v.begin(), v.begin() + corners);
               }
               return to_array(flat, corners);
             };
             std::vector<double> sweeps;
             for (const auto& corners : memory.sweeps) sweeps.insert(sweeps.end(), corners.begin(), corners.end());
             py::dict out;
             out["scalpel"] = memory.scalpel ? py::object(to_array(std::vector<double>(memory.scalpel->begin(), memory.scalpel->end()), 3))
                                             : py::object(py::none());
             out["cut_configuration"] = to_array(memory.cut_configuration, 3);
             out["placed"] = to_array(std::vector<std::int64_t>(memory.placed.begin(), memory.placed.end()), 1);
             out["joined"] = rows(memory.joined, 3);
             out["incision"] = rows(memory.incision, 3);
             out["sweeps"] = to_array(sweeps, 9);
             out["previous_touched"] = rows(memory.previous_touched, 4);
             return out;
           })
      .def("restore", [](TetrahedralCutter& c, const py::dict& given) {
             CutterMemory memory;
             const auto simplexes = [&](const char* key) {
               const auto rows = given[key].cast<IndexArray>();
               std::vector<Simplex> out;
               const auto corners = rows.ndim() == 2 ? rows.shape(1) : 0;
               for (py::ssize_t i = 0; corners > 0 && i < rows.shape(0); ++i) {
                 std::vector<VertexId> v;
                 for (py::ssize_t k = 0; k < corners; ++k) v.push_back(static_cast<VertexId>(rows.at(i, k)));
                 out.emplace_back(1, v);
               }
               return out;
             };
             if (!given["scalpel"].is_none()) {
               const auto scalpel = given["scalpel"].cast<DoubleArray>();
               if (scalpel.size() != 6) throw std::invalid_argument("restore: the scalpel is 6 numbers");
               memory.scalpel.emplace();
               std::copy_n(scalpel.data(), 6, memory.scalpel->begin());
             }
             const auto configuration = given["cut_configuration"].cast<DoubleArray>();
             memory.cut_configuration.assign(configuration.data(), configuration.data() + configuration.size());
             const auto placed = given["placed"].cast<IndexArray>();
             for (py::ssize_t i = 0; i < placed.size(); ++i) memory.placed.push_back(static_cast<VertexId>(placed.data()[i]));
             memory.joined = simplexes("joined");
             memory.incision = simplexes("incision");
             memory.previous_touched = simplexes("previous_touched");
             const auto sweeps = given["sweeps"].cast<DoubleArray>();
             for (py::ssize_t i = 0; i + 9 <= sweeps.size(); i += 9) {
               std::array<double, 9> corners{};
               std::copy_n(sweeps.data() + i, 9, corners.begin());
               memory.sweeps.push_back(corners);
             }
             c.restore(memory);
           }, py::arg("memory"));
}

}  // namespace snede::bindings
