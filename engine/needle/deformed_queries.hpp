// Queries on a deformed triangle (2D) or tetrahedral (3D) mesh, points X + u, for the needle
// (§6.4, §6.9): where a point of space lies in the reference configuration, and which mesh
// edges (2D) or faces (3D) the shaft crosses. They scan the elements (O(n) per call): a few
// microseconds per thousand elements.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "mesh/deformed_positions.hpp"
#include "mesh/mesh.hpp"

namespace snede {

// A point of the needle's space; in 2D the third coordinate is 0.
using Point = Point3;

// The reference position of the material point that sits at x in the deformed mesh (the
// barycentric coordinates of x in the deformed element containing it, applied to the
// reference corners), or nothing if x is outside the deformed body. u: (n_points, dim).
std::optional<Point> reference_position(const Mesh& mesh, std::span<const double> u, const Point& x);

struct ShaftCrossing {
  VertexId near;  // the crossed edge's (face's) vertex closest to the shaft's line
  double s = 0;   // where the segment crosses it, as a distance from the segment's start
  bool on_boundary = false;
};

// Every mesh edge (2D) or face (3D) whose deformed image the segment a→b crosses (touching
// counts, an edge lying along it does not), each once. u: (n_points, dim).
std::vector<ShaftCrossing> shaft_crossings(const Mesh& mesh, std::span<const double> u, const Point& a,
                                           const Point& b);

}  // namespace snede
