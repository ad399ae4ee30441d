// Distances between a segment and the simplexes of a mesh, for refinement along a needle's
// shaft (§6.9): which elements the tube of radius r around the shaft meets. Exact up to
// rounding (closest points, no bounding volumes), so a tube refines only what it touches.
#pragma once

#include <span>

#include "core/vec3.hpp"

namespace snede {

double point_triangle_distance(const Point3& p, const Point3& t0, const Point3& t1, const Point3& t2);

struct ClosestPoints {
  double s, t, distance;  // a + s (b − a) and c + t (d − c), both in [0, 1]
};
// The nearest points of segments a–b and c–d (either may be a point).
ClosestPoints segment_closest_points(const Point3& a, const Point3& b, const Point3& c, const Point3& d);
double segment_segment_distance(const Point3& a, const Point3& b, const Point3& c, const Point3& d);
// The segment a–b against the closed triangle t0 t1 t2 (any orientation in space).
double segment_triangle_distance(const Point3& a, const Point3& b, const Point3& t0, const Point3& t1,
                                 const Point3& t2);
// The segment a–b against the closed simplex with these corners: 3 (a triangle, in the plane
// z = 0 for 2D meshes or anywhere in space) or 4 (a tetrahedron, of either orientation).
double segment_simplex_distance(const Point3& a, const Point3& b, std::span<const Point3> corners);

}  // namespace snede
