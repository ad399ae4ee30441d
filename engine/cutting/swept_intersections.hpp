// Intersections of a line-segment scalpel with a triangulated surface (§5.3): where the
// scalpel pierces a triangle, and when a scalpel moving with constant end-point velocities
// first crosses an edge (equation (5.1), Figure 5.15). Whether they meet is decided by exact
// orientation predicates wherever a sign suffices; the parameters of a meeting are rounded.
#pragma once

#include <array>
#include <optional>

#include "cutting/sweep_triangle.hpp"

namespace snede {

struct TriangleHit {
  std::array<double, 3> weights;  // barycentric coordinates of the hit in the triangle (a, b, c)
  double along = 0;               // fraction along the segment p→q
};

// Where segment p→q meets the closed triangle (a, b, c). A segment crossing the plane is
// tested exactly (orientation_3d of its ends against the plane, and of the triangle's sides
// against its line); a segment lying exactly in the plane (the scalpel flat on the surface)
// meets it along a piece, of which the point nearest `near` is returned. Nothing for a
// degenerate triangle.
std::optional<TriangleHit> segment_meets_triangle(const Point3& p, const Point3& q, const Point3& a, const Point3& b,
                                                  const Point3& c, const Point3& near);

// The distance from point x to segment p→q.
double segment_point_distance(const Point3& p, const Point3& q, const Point3& x);

struct SweptCrossing {
  double time = 0;   // γ: the scalpel is h0 + γ (h1 − h0) → t0 + γ (t1 − t0)
  double along = 0;  // λ: fraction along the scalpel, from its first end
  double on_edge = 0;  // μ: the crossing is a + μ (b − a)
};

// The first time the scalpel, moving from segment h0→t0 to segment h1→t1, meets segment
// (a, b): the scalpel's line and the edge's are coplanar at the roots of a quadratic in γ
// (the thesis's equation (5.1) solved for α); a root counts when the two segments meet there
// (within 1e-9 of their lengths). A sweep that stays coplanar with the edge throughout (the
// scalpel moving flat on a flat surface) has no isolated roots: its first contact is at the
// start or where an end of one segment touches the other (an end of the scalpel crossing the
// edge's line, or the scalpel's line passing an end of the edge), solved in the plane.
std::optional<SweptCrossing> swept_segment_meets_edge(const Point3& h0, const Point3& t0, const Point3& h1,
                                                      const Point3& t1, const Point3& a, const Point3& b);

// The distance between the lines through p, q and through a, b (between the segments'
// nearest points when the lines are parallel).
double line_distance(const Point3& p, const Point3& q, const Point3& a, const Point3& b);

}  // namespace snede
