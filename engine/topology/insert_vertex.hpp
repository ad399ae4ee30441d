// Vertex insertion (§5.2.2: new nodes behind the scalpel; §5.3.2: an active node inserted in
// an incised triangle): a new vertex inside a cell, or in 3D on a face, as one
// replace_elements of the cells around it.
#pragma once

#include <span>

#include "mesh/mesh.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Inserts a vertex at the point with barycentric coordinates `weights` in element e
// (cell_dim + 1 numbers in the order of e's oriented_vertices(), each ≥ 0, summing to 1).
// All weights positive: e is split into 3 triangles or 4 tetrahedra. In 3D with one zero
// weight the point lies on the face opposite that vertex: the one or two tetrahedra sharing
// the face are split into 3 each. The vertex is added with its barycentric parents (the
// corners with non-zero weight), so watchers interpolate fields onto it.
// Refused, leaving the mesh unchanged, when the point lies on an edge (use split_edge) or is
// a vertex, and when a new cell would not be positively oriented (exact orientation test of
// the rounded position; on a surface, exact collinearity) because the point is too close to
// a side. Throws std::invalid_argument for a dead element or weights that are not barycentric.
EditResult insert_vertex(Mesh& mesh, ElementId e, std::span<const double> weights);

}  // namespace snede
