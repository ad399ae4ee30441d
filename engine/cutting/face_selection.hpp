// §3.2.1 face selection: which faces of the mesh approximate the scalpel's sweep.
//
// Every mesh edge that a sweep triangle crosses marks the end closest to the crossing (the
// lower id when the edge is halved); only an edge's first crossing counts, so that sweeps
// turning back cannot mark all four corners of a tetrahedron. A tetrahedron whose edges mark
// exactly three of its corners selects the face they span (Figure 3.1). Marks persist from
// one sweep triangle to the next for the tetrahedra the scalpel is still in (the incomplete
// ones, Figure 3.2), so successive triangles give one connected cut surface, lagging behind
// the scalpel (Figure 3.4).
//
// The search is local: the tetrahedra the sweep meets are found by a walk across faces from
// those the previous sweep met; only the first contact (no previous sweep, or nothing met
// near it) scans the boundary of the body, and a sweep entirely inside the body with no
// previous contact scans the elements.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cutting/deformed_positions.hpp"
#include "cutting/sweep_triangle.hpp"
#include "mesh/connectivity.hpp"

namespace snede {

struct FaceSelection {
  std::vector<FaceId> faces;       // interior faces to dissect, one of each mate pair
  std::vector<ElementId> touched;  // tetrahedra the sweep triangle meets
  int edges_crossed = 0;           // edges crossed for the first time by this sweep
  int four_marked = 0;             // tetrahedra with all four corners marked (one face chosen)
};

class FaceSelector {
 public:
  // Processes sweep triangle number `sweep_index` against the deformed mesh.
  FaceSelection select(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep, int sweep_index);
  // The sweep that first marked v (its plane is where §3.2.2 snaps v), or −1.
  int marking_sweep(VertexId v) const;
  // Mesh edits the marks must follow: a vertex removed (its id may be reused), and a vertex
  // copied by dissection (the copy's edges keep the original's marks).
  void forget_vertex(VertexId v);
  void copy_vertex(VertexId original, VertexId copy);
  std::size_t n_marks() const { return marks_.size(); }
  // The oldest sweep a remembered mark refers to (older planes are no longer needed), or −1.
  int oldest_sweep() const;

 private:
  struct Mark {
    VertexId node;
    int sweep;
  };
  static std::uint64_t edge_key(VertexId a, VertexId b);
  std::vector<ElementId> seeds(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep) const;
  std::vector<ElementId> walk(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep,
                              std::vector<ElementId> seeds) const;
  void keep_marks_of(const Connectivity& c, const std::vector<ElementId>& elements);

  std::unordered_map<std::uint64_t, Mark> marks_;
  std::unordered_map<VertexId, int> node_sweep_;
  std::vector<ElementId> previous_touched_;
};

}  // namespace snede
