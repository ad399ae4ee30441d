// The labelling of a starting element for bisection (§6.5): which edge is bisected first
// and in which order the others follow.
//
// 2D: the longest edge (the hypotenuse of a right triangle; ties broken by vertex ids), so
// that §6.5's bisect is longest-edge and newest-vertex bisection at once.
// 3D: the vertices sorted by id with tag 3 (refinement edge from the lowest to the highest
// id). On the Kuhn box of snede.meshing.box ids grow along each cube's path 000→111, so this
// is Maubach's compatible labelling of the Kuhn split (3 similarity classes). On any other
// mesh it is the sorted-global-order labelling of Alkämper, Gaspoz and Klöfkorn; Bisection
// detects at run time when its recursive completion would not terminate and then forces the
// split (Bisection::bisect).
#pragma once

#include "mesh/mesh.hpp"
#include "topology/tagged_simplex.hpp"

namespace snede {

TaggedSimplex initial_labelling(const Mesh& mesh, const Simplex& element);

}  // namespace snede
