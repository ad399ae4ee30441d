// §5.2.2 edge flip on triangle meshes (2D and surfaces, §5.3.1): the two triangles sharing
// an edge are replaced by the two sharing the quadrilateral's other diagonal (Figure 7.4).
#pragma once

#include "mesh/mesh.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Replaces the triangles (a, b, c) and (b, a, d) by (a, d, c) and (b, c, d) — one
// replace_elements — keeping their orientation. Refused, leaving the mesh unchanged, when
// (a, b) is not an edge or lies on the boundary, when the new edge (c, d) already exists
// (Figure 5.9: the flip would duplicate it or make it non-manifold), when in 2D the
// quadrilateral (a, d, b, c) is not strictly convex (exact orientation_2d of both new
// triangles must be +1), and on a surface when a new triangle would be degenerate (exact
// collinear_3d) or fold over: its normal points against the quadrilateral's vector area (see
// RetriangulationPlane) or against either old triangle's normal — floating-point tests, the
// only ones here that are not exact.
// Throws std::invalid_argument for a tetrahedral mesh.
EditResult flip_edge(Mesh& mesh, VertexId a, VertexId b);

// §5.2.1: whether interior edge (a, b) of a triangle mesh is legal: the vertex opposite it in
// one triangle is not strictly inside the other's circumcircle (exact in_circle; cocircular is
// legal). Boundary edges are Delaunay. On a surface (§5.3.1) the two triangles are unfolded
// into one plane: when their four corners are exactly coplanar (orientation_3d) the exact
// in_circle of their projection onto the coordinate plane facing their normal decides, as in
// 2D; otherwise the edge is illegal when the two angles facing it add up to more than
// π (1 + 1e-12) — the unfolded criterion, a floating-point one, with a margin so that nearly
// cocircular corners are never flipped back and forth. Throws std::invalid_argument if (a, b)
// is not an edge or the mesh is tetrahedral.
bool is_locally_delaunay(const Mesh& mesh, VertexId a, VertexId b);
// The same for edge (a, b) of a known live triangle, in O(1) (a neighbour look-up, no star).
bool is_locally_delaunay(const Mesh& mesh, ElementId triangle, VertexId a, VertexId b);

}  // namespace snede
