// What a Delaunay cut of a triangle mesh (§5.2) or a surface (§5.3) did: its moves, flips,
// node insertions and removals, entries and exits, and the triangle counts before and after.
#pragma once

#include <cstddef>
#include <string>

namespace snede {

// What one move (or several, added up) did to the mesh.
struct PlanarCutResult {
  int moves = 0;
  int flips = 0;
  int nodes_removed = 0;
  int nodes_inserted = 0;
  int incision_splits = 0;   // Figure 5.5: each inserts a node on both lips
  int edges_contracted = 0;  // short edges left by an exit (Figure 5.7)
  int entries = 0;
  int exits = 0;
  int branches = 0;          // surfaces: an incision branching at a fold (Figure 5.14)
  int annihilations = 0;     // surfaces: incisions meeting and ending together (Figure 5.13)
  int stuck = 0;             // moves that left the active node short of the scalpel
  std::size_t triangles_before = 0;
  std::size_t triangles_after = 0;
  double seconds = 0;

  // Accumulates a later report: counts and times add, triangles_after is the later one's.
  void add(const PlanarCutResult& later);
  // Every field with its name: the one list that bindings and printing read.
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("moves", &PlanarCutResult::moves);
    visit("flips", &PlanarCutResult::flips);
    visit("nodes_removed", &PlanarCutResult::nodes_removed);
    visit("nodes_inserted", &PlanarCutResult::nodes_inserted);
    visit("incision_splits", &PlanarCutResult::incision_splits);
    visit("edges_contracted", &PlanarCutResult::edges_contracted);
    visit("entries", &PlanarCutResult::entries);
    visit("exits", &PlanarCutResult::exits);
    visit("branches", &PlanarCutResult::branches);
    visit("annihilations", &PlanarCutResult::annihilations);
    visit("stuck", &PlanarCutResult::stuck);
    visit("triangles_before", &PlanarCutResult::triangles_before);
    visit("triangles_after", &PlanarCutResult::triangles_after);
    visit("seconds", &PlanarCutResult::seconds);
  }
};

// One line for people: moves, flips, nodes, entries and exits (on surfaces branches and
// annihilations), triangles before and after, time.
std::string summary(const PlanarCutResult& report);

}  // namespace snede
