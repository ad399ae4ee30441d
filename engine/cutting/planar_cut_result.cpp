#include "cutting/planar_cut_result.hpp"

#include "core/formatted.hpp"

namespace snede {

void PlanarCutResult::add(const PlanarCutResult& later) {
  if (moves == 0) triangles_before = later.triangles_before;
  moves += later.moves;
  flips += later.flips;
  nodes_removed += later.nodes_removed;
  nodes_inserted += later.nodes_inserted;
  incision_splits += later.incision_splits;
  edges_contracted += later.edges_contracted;
  entries += later.entries;
  exits += later.exits;
  branches += later.branches;
  annihilations += later.annihilations;
  stuck += later.stuck;
  triangles_after = later.triangles_after;
  seconds += later.seconds;
}

std::string summary(const PlanarCutResult& r) {
  std::string line = std::to_string(r.moves) + " moves: " + std::to_string(r.flips) + " flips, " +
                     std::to_string(r.nodes_removed) + " nodes removed, " + std::to_string(r.nodes_inserted) +
                     " inserted (" + std::to_string(r.incision_splits) + " incision splits), " +
                     std::to_string(r.entries) + " entries, " + std::to_string(r.exits) + " exits";
  if (r.branches || r.annihilations)
    line += ", " + std::to_string(r.branches) + " branches, " + std::to_string(r.annihilations) + " annihilations";
  return line + formatted("; %zu \u2192 %zu triangles in %.2f ms", r.triangles_before, r.triangles_after,
                          r.seconds * 1e3);
}

}  // namespace snede
