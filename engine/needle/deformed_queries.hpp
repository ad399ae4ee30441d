// Queries on a deformed 2D triangle mesh (points X + u) for the needle (§6.4): where a point
// of space lies in the reference configuration, and which mesh edges the shaft crosses.
// They scan the elements (O(n) per call); the needle's meshes are small and the scan is a few
// microseconds per thousand triangles.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

using Point2 = std::array<double, 2>;

// Where vertex v is in the deformed mesh: X_v + u_v. u: (n_points, 2).
Point2 deformed_point(const Mesh& mesh, std::span<const double> u, VertexId v);

// The reference position of the material point that sits at x in the deformed mesh (the
// barycentric coordinates of x in the deformed triangle containing it, applied to the
// reference corners), or nothing if x is outside the deformed body. u: (n_points, 2).
std::optional<Point2> reference_position(const Mesh& mesh, std::span<const double> u, const Point2& x);

struct ShaftCrossing {
  VertexId near, far;  // the edge's end closest to the shaft's line, and the other end
  double s = 0;        // where the edge crosses the segment, as a distance from its start
  bool on_boundary = false;
};

// Every mesh edge whose deformed image crosses the segment a→b (touching counts, an edge
// lying along it does not), each once. u: (n_points, 2).
std::vector<ShaftCrossing> shaft_crossings(const Mesh& mesh, std::span<const double> u, const Point2& a,
                                           const Point2& b);

}  // namespace snede
