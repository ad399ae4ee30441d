#include "cutting/cut_result.hpp"

#include "core/formatted.hpp"

namespace snede {

void CutResult::add(const CutResult& o) {
  sweeps += o.sweeps;
  faces_selected += o.faces_selected;
  faces_dissected += o.faces_dissected;
  vertices_split += o.vertices_split;
  vertices_snapped += o.vertices_snapped;
  snaps_refused += o.snaps_refused;
  degenerate_found += o.degenerate_found;
  for (int k = 0; k < 4; ++k) degenerate_shapes[k] += o.degenerate_shapes[k];
  edges_collapsed += o.edges_collapsed;
  edges_split += o.edges_split;
  faces_split += o.faces_split;
  elements_cut_free += o.elements_cut_free;
  if (o.sweeps > 0 || sweeps == 0) components = o.components;  // the later count, unless it swept nothing
  if (!o.piece_elements.empty()) piece_elements = o.piece_elements;
  free_pieces += o.free_pieces;
  pieces_fixed += o.pieces_fixed;
  fragments_removed += o.fragments_removed;
  fragment_elements += o.fragment_elements;
  piece_search += o.piece_search;
  seconds += o.seconds;
}

std::string summary(const CutResult& r) {
  return formatted(
      "%d faces dissected (%d vertices snapped, %d refused), %d degenerate: %d collapses, %d splits, %d cut free, "
      "%d fragments removed; %d pieces in %.2f ms",
      r.faces_dissected, r.vertices_snapped, r.snaps_refused, r.degenerate_found, r.edges_collapsed, r.edges_split,
      r.elements_cut_free, r.fragments_removed, r.components, r.seconds * 1e3);
}

}  // namespace snede
