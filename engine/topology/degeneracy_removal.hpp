// §3.2.3 degeneracy removal: the flat tetrahedra that node snapping leaves (Figure 3.7)
// collapsed away, in passes, by the element's shape (Figures 3.8–3.9).
//
// A tetrahedron is degenerate when its aspect ratio (minimum height over maximum edge, in
// the reference configuration) is below a threshold. Its shape is the number of its dihedral
// angles above `large_angle`:
//  * needle (none): the shortest edge is collapsed;
//  * spindle (one): the edge opposite the large angle is split where it passes the large
//    angle's edge, then the short edge from the new vertex is collapsed;
//  * sliver (two, at opposite edges): both edges are split where they pass each other, and the
//    short edge between the new vertices is collapsed;
//  * cap (three, around a face): a vertex is inserted in that face below the opposite corner,
//    and the short edge between them is collapsed.
// Collapses keep a boundary vertex where they can (the body's shape and the cut surface stay
// put) and are refused, never forced, when they would change the topology or invert an
// element (Figure 3.10); a split whose collapse is refused is undone. Within a pass, caps go
// first, then slivers, spindles and needles, the flattest first. After a pass the degenerate
// elements are listed again; passes continue while the list shrinks (at most 8). What remains
// is cut free (dissected along its faces) and removed.
#pragma once

#include <array>
#include <numbers>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

struct DegeneracyOptions {
  double min_aspect_ratio = 0.01;
  double large_angle = 0.99 * std::numbers::pi;
};

enum class DegenerateShape { needle = 0, spindle = 1, sliver = 2, cap = 3 };

struct DegeneracyReport {
  int found = 0;                    // degenerate elements in the first list
  std::array<int, 4> by_shape{};    // of those, needles, spindles, slivers, caps
  int edges_collapsed = 0;
  int edges_split = 0;              // splits kept (those undone are not counted)
  int faces_split = 0;              // cap insertions kept
  int cut_free = 0;                 // incollapsible elements cut free and removed
  int passes = 0;
};

// The shape class of a tetrahedron (corners (4, 3)): its number of large dihedral angles, 3
// for three or more.
DegenerateShape degenerate_shape(std::span<const double> corners, double large_angle);

// Removes the degenerate elements among those containing a vertex of `region` (the vertices
// an edit moved or created; the search, like the edit, stays local). Throws
// std::invalid_argument for a mesh that is not tetrahedral or thresholds outside
// 0 < min_aspect_ratio < 1, 0 < large_angle < π.
DegeneracyReport remove_degeneracies(Mesh& mesh, const std::vector<VertexId>& region, const DegeneracyOptions& options);

}  // namespace snede
