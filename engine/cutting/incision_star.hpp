// What the Delaunay cutters (§5.2 in the plane, §5.3 on surfaces) ask of the triangles around
// an incision's active node, the same in both: its star as wedges, boundary tests, the flips
// towards Delaunay, and the lips' edges.
#pragma once

#include <unordered_set>
#include <vector>

#include "mesh/mesh.hpp"
#include "topology/flip_edge.hpp"

namespace snede {

struct Wedge {  // triangle (b, y, z) of b's star, in its orientation
  ElementId element;
  VertexId y, z;
};

std::vector<Wedge> star_wedges(const Connectivity& c, VertexId b);

// Whether the edge of `triangle` opposite its vertex `opposite` is on the boundary.
bool is_boundary_edge(const Connectivity& c, ElementId triangle, VertexId opposite);

// Whether v is on the boundary: an edge of its star from it or opposite it is.
bool touches_boundary(const Connectivity& c, VertexId v);

// The edges of the active triangles (link edges and spokes from b) flipped while one fails
// the (unfolded) empty-circle test and `flip(p, q)` performs its flip (§5.2.2, §5.3.1).
template <class Flip>
void flip_star_towards_delaunay(const Mesh& mesh, VertexId b, const Flip& flip) {
  for (int round = 0; round < 64; ++round) {
    bool flipped = false;
    for (const Wedge& w : star_wedges(mesh.connectivity(), b)) {
      for (const auto& [p, q] : {std::pair{w.y, w.z}, std::pair{b, w.y}})
        if (!is_locally_delaunay(mesh, w.element, p, q) && flip(p, q)) {
          flipped = true;
          break;
        }
      if (flipped) break;
    }
    if (!flipped) break;
  }
}

// The boundary edges with both ends among `incision_vertices` (both lips), flattened pairs.
std::vector<VertexId> lip_edges(const Connectivity& c, const std::unordered_set<VertexId>& incision_vertices);

}  // namespace snede
