// §3.2.2 node snapping: a vertex of the cut surface moved onto the sweep, so that the
// incision is smooth rather than jagged (Figure 3.5).
//
// In the deformed configuration an interior vertex is projected orthogonally onto the plane
// of its sweep triangle; a boundary vertex, so as not to change the shape of a flat surface,
// onto the line where that plane meets each boundary face around it, keeping the projection
// closest to the vertex that lies in its face (Figure 3.6). The point is taken back to the
// reference configuration through the tetrahedron around the vertex that contains it (the
// barycentric coordinates of the point in the deformed tetrahedron, applied to its reference
// corners), which carries the displacement with it: the vertex's deformed position becomes
// exactly the snapped point, up to rounding.
#pragma once

#include "cutting/deformed_positions.hpp"
#include "cutting/sweep_triangle.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Refused, leaving the mesh unchanged, when no boundary face around a boundary vertex meets
// the plane within the face, when no tetrahedron around the vertex contains the point (the
// thesis's failed repositioning), or when the move would make an element of the vertex's
// star flat or inverted in the reference or the deformed configuration.
EditResult snap_to_sweep(Mesh& mesh, const DeformedPositions& x, VertexId v, const SweepTriangle& plane);

}  // namespace snede
