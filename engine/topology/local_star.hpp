// The star of a vertex as a local edit needs it: every element containing the vertex, and
// whether they form one face-connected fan (§7.3 star; a pinched vertex has several).
#pragma once

#include <vector>

#include "mesh/connectivity.hpp"

namespace snede {

struct LocalStar {
  std::vector<ElementId> elements;  // every live element containing the vertex
  bool face_connected = true;       // false for a pinched (non-manifold) vertex
};

// Walks from the vertex's recorded element across faces containing it; only when that walk
// misses some of the n_vertex_uses(v) elements does it scan the whole mesh.
LocalStar local_star(const Connectivity& c, VertexId v);

// The elements having both a and b as vertices (those around edge (a, b)).
std::vector<ElementId> elements_with_edge(const Connectivity& c, VertexId a, VertexId b);

// The vertex of a triangle other than a and b. Throws std::logic_error if there is none.
VertexId third_vertex(const Simplex& triangle, VertexId a, VertexId b);

// True if some element has both a and b as vertices.
inline bool has_edge(const Connectivity& c, VertexId a, VertexId b) { return !elements_with_edge(c, a, b).empty(); }

}  // namespace snede
