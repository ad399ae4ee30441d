// The labelling of elements for bisection (§6.5): which edge is bisected first and which
// edges the halves bisect next.
//
// 2D: the longest edge of a starting element (the hypotenuse of a right triangle; ties broken
// by vertex ids), then newest-vertex bisection, so that §6.5's bisect is longest-edge and
// newest-vertex bisection at once.
// 3D, two rules:
// * newest_vertex: the vertices sorted by id with tag 3 (refinement edge from the lowest to the
//   highest id), then Maubach's children. On the Kuhn box of snede.meshing.box ids grow along
//   each cube's path 000→111, so this is Maubach's compatible labelling of the Kuhn split
//   (3 similarity classes, uniform refinement doubles the count exactly).
// * longest_edge: every element, starting or made by a split, bisects its longest edge (total
//   order: squared length, then the larger id, then the smaller), Rivara's longest-edge
//   bisection. §6.5's recursion then follows edges of strictly growing order, so it ends
//   without forced splits, and it stays near the refined region on unstructured meshes, where
//   the sorted labelling bisects arbitrary edges: along a 30 mm needle shaft into a gmsh
//   liver of 21 062 tetrahedra at h = 2.5 mm it adds 5 700 cells, the sorted labelling 9 600.
// A mesh whose sorted labelling already bisects every element's longest edge (the Kuhn box)
// gets newest_vertex; any other 3D mesh longest_edge.
#pragma once

#include <array>

#include "mesh/mesh.hpp"
#include "topology/tagged_simplex.hpp"

namespace snede {

enum class BisectionRule { newest_vertex, longest_edge };

// The rule for a mesh about to be refined (see above); O(elements).
BisectionRule bisection_rule_for(const Mesh& mesh);

TaggedSimplex initial_labelling(const Mesh& mesh, const Simplex& element, BisectionRule rule);

// The labels of the halves when `label`'s refinement edge is bisected at `midpoint` (a vertex
// of the mesh already): children[0] keeps the refinement edge's start, children[1] its end.
std::array<TaggedSimplex, 2> labels_of_halves(const Mesh& mesh, const TaggedSimplex& label, VertexId midpoint,
                                              BisectionRule rule);

}  // namespace snede
