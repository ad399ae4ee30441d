// What a tetrahedral cut (§3.2) did: the counts of each stage of a sweep, the pieces after it,
// and its time. A report of several sweeps is their sum (add).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace snede {

struct CutResult {
  int sweeps = 0;              // sweep triangles processed
  int faces_selected = 0;
  int faces_dissected = 0;     // selected faces the dissection opened (others stay joined, Figure 7.7)
  int vertices_split = 0;      // vertex copies the dissection made
  int vertices_snapped = 0;
  int snaps_refused = 0;
  int degenerate_found = 0;
  std::array<int, 4> degenerate_shapes{};  // needles, spindles, slivers, caps among them
  int edges_collapsed = 0;
  int edges_split = 0;
  int faces_split = 0;         // cap removals: a vertex inserted in a face
  int elements_cut_free = 0;
  int components = 0;          // pieces of the body after the cut
  int free_pieces = 0;         // after a sweep that separated a piece: pieces not held (fewer constrained
                               // displacement components than their 6 rigid motions)
  int pieces_fixed = 0;        // of those, fixed on one face (fix_free_pieces)
  int fragments_removed = 0;   // separated pieces of at most max_fragment_elements (by volume), removed
  int fragment_elements = 0;   // the elements they had
  // After a sweep that separated a piece: the elements of each piece, largest first (the
  // latest such sweep's when reports are added).
  std::vector<std::size_t> piece_elements;
  std::size_t piece_search = 0;  // elements the local search for separated pieces visited
  double seconds = 0;

  // Accumulates a later report: counts and times add up; components is the later report's
  // unless that one swept nothing.
  void add(const CutResult& other);
  // Every field with its name: the one list that bindings and printing read.
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("sweeps", &CutResult::sweeps);
    visit("faces_selected", &CutResult::faces_selected);
    visit("faces_dissected", &CutResult::faces_dissected);
    visit("vertices_split", &CutResult::vertices_split);
    visit("vertices_snapped", &CutResult::vertices_snapped);
    visit("snaps_refused", &CutResult::snaps_refused);
    visit("degenerate_found", &CutResult::degenerate_found);
    visit("degenerate_shapes", &CutResult::degenerate_shapes);
    visit("edges_collapsed", &CutResult::edges_collapsed);
    visit("edges_split", &CutResult::edges_split);
    visit("faces_split", &CutResult::faces_split);
    visit("elements_cut_free", &CutResult::elements_cut_free);
    visit("components", &CutResult::components);
    visit("free_pieces", &CutResult::free_pieces);
    visit("pieces_fixed", &CutResult::pieces_fixed);
    visit("fragments_removed", &CutResult::fragments_removed);
    visit("fragment_elements", &CutResult::fragment_elements);
    visit("piece_elements", &CutResult::piece_elements);
    visit("piece_search", &CutResult::piece_search);
    visit("seconds", &CutResult::seconds);
  }
};

// One line for people: faces dissected, snaps, degeneracies, pieces, time.
std::string summary(const CutResult& report);

}  // namespace snede
