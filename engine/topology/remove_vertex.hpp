// §5.3.1 vertex removal on triangle meshes (2D and surfaces): the star of a vertex is
// retriangulated without it (Figure 5.10), as one replace_elements followed by
// Mesh::remove_vertex.
#pragma once

#include <functional>

#include "mesh/mesh.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Removes vertex v by retriangulating its link polygon with ears — the result of flipping
// ears until v is in three triangles and then dropping it (Figure 5.10). An ear (three
// consecutive polygon vertices) is valid when its triangle is counter-clockwise in the
// RetriangulationPlane (exactly in 2D; on a surface also not collinear in 3D and not folding
// over against the star's vector area), contains no other remaining polygon vertex and its
// new edge does not already exist in the mesh; ears whose circumcircle holds no other polygon
// vertex (exact in_circle) are taken first, so a convex link gets its Delaunay triangulation.
// A boundary vertex is removed only when it lies exactly on the segment between its two
// boundary neighbours; the open fan of its star is then closed by that segment and
// retriangulated the same way. The whole retriangulation is planned first: refused, leaving
// the mesh unchanged, when it cannot be completed (the greedy ear choice may refuse a link
// with collinear vertices that some other triangulation would handle).
// `acceptable`, when given, may refuse ears too (a cutter's own shape checks), and so may the
// mesh's watchers (ConnectivityWatcher::refuses: a body refuses a triangle its displacement
// would invert, so the carried state stays admissible). Watchers hear
// one change (a ChangeBatch). Throws std::invalid_argument for a tetrahedral mesh or a v that
// is not a live vertex.
using TriangleCheck = std::function<bool(const Simplex&)>;
EditResult remove_vertex_by_flips(Mesh& mesh, VertexId v, const TriangleCheck& acceptable = {});

}  // namespace snede
