// Edge split (§3.2.3: spindles and slivers have edges split before a short edge is collapsed;
// §7.3 replace-elements): a new vertex on edge (a, b) and every element around the edge cut
// in two there. Triangles in 2D, triangulated surfaces in 3D, and tetrahedra.
#pragma once

#include "mesh/mesh.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Adds the vertex (1 − t)·x_a + t·x_b with parents on_edge(a, b, t) (so watchers carry
// fields to it) and replaces each element around (a, b) by its halves, in one
// replace_elements. Returns the new vertex. Refused, leaving the mesh unchanged, unless
// 0 < t < 1 and (a, b) is an edge of the mesh, or if a half would be flat or inverted (the
// rounded new point may miss the line through a, b of a nearly flat element).
EditResult split_edge(Mesh& mesh, VertexId a, VertexId b, double t);

}  // namespace snede
