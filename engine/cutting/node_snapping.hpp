// §3.2.2 node snapping: a vertex of the cut surface moved onto the sweep, so that the
// incision is smooth rather than jagged (Figure 3.5).
//
// In the deformed configuration an interior vertex is projected orthogonally onto the plane
// of its sweep triangle; a boundary vertex, so as not to change the shape of a flat surface,
// onto the segment where that plane crosses each boundary face around it (its point closest to
// the vertex), keeping the candidate closest to the vertex (Figure 3.6). The thesis projects
// onto the line and drops a projection outside the face, which fails at corners and edges of
// the body where the line's nearest point lies beyond the face; the segment's nearest point
// is always in the face. On a crease of the body (faces meeting at more than 30°: an edge or
// a corner of a box) the vertex may only move along the crease, so that the body keeps its
// shape; a corner does not move. The point is taken back to the
// reference configuration through the tetrahedron around the vertex that contains it (the
// barycentric coordinates of the point in the deformed tetrahedron, applied to its reference
// corners), which carries the displacement with it: the vertex's deformed position becomes
// exactly the snapped point, up to rounding.
#pragma once

#include "cutting/sweep_triangle.hpp"
#include "mesh/deformed_positions.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Refused, leaving the mesh unchanged, when the plane crosses no boundary face around a
// boundary vertex, when no tetrahedron around the vertex contains the point (the
// thesis's failed repositioning), or when the move would make an element of the vertex's
// star flat or inverted in the reference or the deformed configuration (and, when given, in
// `current`: the body as it is now, when the sweep is made against an earlier configuration;
// there also when it would shrink an element to less than a thousandth of its volume).
EditResult snap_to_sweep(Mesh& mesh, const DeformedPositions& x, VertexId v, const SweepTriangle& plane,
                         const DeformedPositions* current = nullptr);

}  // namespace snede
