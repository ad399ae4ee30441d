// §3.2.1 face selection: which faces of the mesh approximate the scalpel's sweep.
//
// Every mesh edge that a sweep triangle crosses marks the end closest to the crossing (the
// lower id when the edge is halved); only an edge's first crossing counts, so that sweeps
// turning back cannot mark all four corners of a tetrahedron. Snapped onto the sweep, the
// marked vertices leave no edge crossing it, so each tetrahedron near the sweep is on one side
// of it. The thesis selects, per tetrahedron whose edges mark exactly three of its corners, the
// face they span (Figure 3.1); that left holes where two or four corners were marked, and a
// sweep across the whole body left it joined. Here a face is selected when its three corners
// are marked and the tetrahedra on its two sides lie on opposite sides of the sweep: the faces
// between the two sides, a surface without holes across the swept region. Its tetrahedra with
// all four corners marked may come out as one-element pieces; the cutter removes those.
//
// Intersections of earlier sweep triangles count for the tetrahedra the scalpel is still in
// (the incomplete ones, Figure 3.2), so successive triangles give one connected cut surface,
// lagging behind the scalpel (Figure 3.4). The thesis stores those intersections; here the
// selector keeps the last few sweep triangles instead and re-evaluates the crossings of the
// tetrahedra met by the current and the previous sweep, and of the stars of the vertices they
// mark (a face whose last corner is marked now may lie in a tetrahedron no recent sweep met),
// on the mesh as it is now: node snapping has moved vertices since, and stored marks from
// before the move leave gaps in the cut surface. A corner snapped onto a sweep counts as on it.
//
// The tetrahedra a sweep meets are found by a walk across faces from those the previous sweep
// met and from the boundary faces it meets: a scan of the boundary with every sweep (a box
// test per face), so that a blade entering the body again elsewhere (the far side of a torus's
// ring, another lobe) is seen at once; a sweep entirely inside the body with no previous
// contact scans the elements.
#pragma once

#include <deque>
#include <unordered_map>
#include <utility>
#include <vector>

#include "cutting/sweep_triangle.hpp"
#include "mesh/connectivity.hpp"
#include "mesh/deformed_positions.hpp"

namespace snede {

struct FaceSelection {
  std::vector<FaceId> faces;       // interior faces to dissect, one of each mate pair
  std::vector<ElementId> touched;  // tetrahedra the sweep triangle meets
  std::unordered_map<VertexId, SweepTriangle> plane;  // per vertex of `faces`: the sweep that marked it
};

class FaceSelector {
 public:
  // How many recent sweep triangles count for first crossings: a tetrahedron must be crossed
  // completely within this many (32 scalpel moves), so steps shorter than about 1/30 of an
  // element cut nothing. Each edge is tested only against sweeps whose boxes it meets.
  static constexpr std::size_t remembered_sweeps = 64;

  // Processes the next sweep triangle against the deformed mesh.
  FaceSelection select(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep);
  // Forgets the earlier sweeps: the next one is a first contact.
  void forget() {
    sweeps_.clear();
    previous_touched_.clear();
  }
  // What the next selection depends on besides the mesh: the remembered sweeps (oldest first)
  // and the tetrahedra the latest one met; restore() takes them back (a cutter going on in a
  // renumbered copy of its mesh).
  const std::deque<SweepTriangle>& remembered() const { return sweeps_; }
  const std::vector<ElementId>& previous_touched() const { return previous_touched_; }
  void restore(std::deque<SweepTriangle> sweeps, std::vector<ElementId> previous_touched) {
    sweeps_ = std::move(sweeps);
    previous_touched_ = std::move(previous_touched);
  }

 private:
  std::vector<ElementId> seeds(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep) const;
  std::vector<ElementId> walk(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep,
                              std::vector<ElementId> seeds) const;

  std::deque<SweepTriangle> sweeps_;  // oldest first, the current one last
  std::vector<ElementId> previous_touched_;
};

}  // namespace snede
