// Edge collapse (§3.2.3, Figure 3.10): the two vertices of an edge merged into one, the
// elements around the edge removed. The thesis collapses the short edges left by flat
// elements; a collapse that would make the mesh non-manifold (Figure 3.10) or turn an
// element inside out is refused. 2D, 3D and triangulated surfaces.
#pragma once

#include "mesh/mesh.hpp"
#include "topology/edit_result.hpp"

namespace snede {

// Merges `gone` into `keep`: the elements containing both are removed (replace_elements),
// the rest of gone's star gets gone → keep (change_elements, §7.3: a collapse is a
// substitution), keep moves to (1 − t)·x_keep + t·x_gone with parents on_edge(keep, gone, t)
// when t ≠ 0, and gone is removed — one ChangeBatch, so watchers hear of it once.
//
// Refused, leaving the mesh unchanged, when
//  * t is not in [0, 1], or (keep, gone) is not an edge;
//  * keep or gone is a pinched vertex (its star is not face-connected);
//  * the link condition fails: Lk(keep) ∩ Lk(gone) ≠ Lk(keep gone), with the boundary
//    closed off by a virtual vertex joined to every boundary face (Dey–Edelsbrunner), so that
//    the collapse would change the topology — Figure 3.10, and in particular an interior
//    edge joining two boundary vertices;
//  * a surviving element would be flat or inverted at the new position of keep (exact
//    signs in 2D and 3D; see orientation_checks.hpp for surfaces);
//  * on a tetrahedral mesh, the collapse would change the body's volume beyond round-off: it
//    would move the boundary (a boundary vertex off its flat patch), and the cells would no
//    longer fill the body they filled (the 2D cutters' exit contractions, §5.3.2, may);
//  * with t = 0, a watcher refuses a cell of gone's star with keep in gone's place that it did
//    not refuse before (a body: the cell inverted by its displacement, issue 48).
EditResult collapse_edge(Mesh& mesh, VertexId keep, VertexId gone, double t = 0);

}  // namespace snede
