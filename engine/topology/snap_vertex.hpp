// §3.2 node snapping: a vertex moved in the reference configuration onto a nearby feature
// (an edge point, a face point) so that a cut passes through it instead of leaving slivers.
#pragma once

#include "mesh/mesh.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Moves v to the weighted sum of `target`'s vertices (which may include v; fields are
// re-interpolated by the mesh's watchers). Refused, leaving the mesh unchanged, when v is not
// a vertex in use or when an element of v's star would become flat or inverted (exact signs;
// see orientation_checks.hpp for surfaces). Throws std::invalid_argument, before changing
// anything, for parents that are not live vertices or weights that are not barycentric.
EditResult snap_vertex(Mesh& mesh, VertexId v, const VertexParents& target);

}  // namespace snede
