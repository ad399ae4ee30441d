#include "core/segment_distance.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace snede {
namespace {

// Ericson, Real-Time Collision Detection (2005) §5.1.5: the point of the triangle closest to p,
// by the Voronoi region of p (vertex, edge or face).
Point3 closest_point_on_triangle(const Point3& p, const Point3& a, const Point3& b, const Point3& c) {
  const Point3 ab = minus(b, a), ac = minus(c, a), ap = minus(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Point3 bp = minus(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return plus_scaled(a, d1 / (d1 - d3), ab);
  const Point3 cp = minus(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return plus_scaled(a, d2 / (d2 - d6), ac);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return plus_scaled(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), minus(c, b));
  const double denominator = va + vb + vc;
  if (!(denominator > 0)) return a;  // a degenerate triangle whose regions all failed: one corner
  return plus_scaled(plus_scaled(a, vb / denominator, ab), vc / denominator, ac);
}

// Whether p lies in the closed tetrahedron: the four signed volumes with p in place of one corner
// all have the sign of the whole (either orientation).
bool tetrahedron_contains(const Point3& p, std::span<const Point3> t) {
  auto volume = [](const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
    return dot(minus(b, a), cross(minus(c, a), minus(d, a)));
  };
  const double whole = volume(t[0], t[1], t[2], t[3]);
  const double parts[4] = {volume(p, t[1], t[2], t[3]), volume(t[0], p, t[2], t[3]), volume(t[0], t[1], p, t[3]),
                           volume(t[0], t[1], t[2], p)};
  return std::all_of(std::begin(parts), std::end(parts), [&](double v) { return v * whole >= 0; });
}

}  // namespace

double point_triangle_distance(const Point3& p, const Point3& t0, const Point3& t1, const Point3& t2) {
  return distance(p, closest_point_on_triangle(p, t0, t1, t2));
}

ClosestPoints segment_closest_points(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  // Ericson §5.1.9: minimise |a + s (b − a) − c − t (d − c)| over the unit square, degenerate
  // segments (points) included.
  const Point3 d1 = minus(b, a), d2 = minus(d, c), r = minus(a, c);
  const double aa = dot(d1, d1), ee = dot(d2, d2), f = dot(d2, r);
  double s = 0, t = 0;
  if (aa <= 0 && ee > 0) {
    t = std::clamp(f / ee, 0.0, 1.0);
  } else if (aa > 0) {
    const double cc = dot(d1, r);
    if (ee <= 0) {
      s = std::clamp(-cc / aa, 0.0, 1.0);
    } else {
      const double bb = dot(d1, d2), denominator = aa * ee - bb * bb;
      s = denominator > 0 ? std::clamp((bb * f - cc * ee) / denominator, 0.0, 1.0) : 0.0;
      t = (bb * s + f) / ee;
      if (t < 0) {
        t = 0;
        s = std::clamp(-cc / aa, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((bb - cc) / aa, 0.0, 1.0);
      }
    }
  }
  return {s, t, distance(plus_scaled(a, s, d1), plus_scaled(c, t, d2))};
}

double segment_segment_distance(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  return segment_closest_points(a, b, c, d).distance;
}

double segment_triangle_distance(const Point3& a, const Point3& b, const Point3& t0, const Point3& t1,
                                 const Point3& t2) {
  // Two disjoint convex sets are closest at an endpoint of the segment or on an edge of the
  // triangle; a segment that pierces the triangle is at 0, checked at its crossing of the plane.
  double nearest = std::min({point_triangle_distance(a, t0, t1, t2), point_triangle_distance(b, t0, t1, t2),
                             segment_segment_distance(a, b, t0, t1), segment_segment_distance(a, b, t1, t2),
                             segment_segment_distance(a, b, t2, t0)});
  const Point3 normal = cross(minus(t1, t0), minus(t2, t0));
  const double da = dot(normal, minus(a, t0)), db = dot(normal, minus(b, t0));
  if ((da < 0 && db > 0) || (da > 0 && db < 0))
    nearest = std::min(nearest, point_triangle_distance(lerp(a, b, da / (da - db)), t0, t1, t2));
  return nearest;
}

double segment_simplex_distance(const Point3& a, const Point3& b, std::span<const Point3> corners) {
  if (corners.size() == 3) return segment_triangle_distance(a, b, corners[0], corners[1], corners[2]);
  if (corners.size() != 4)
    throw std::invalid_argument("segment_simplex_distance: a simplex has 3 or 4 corners, got " +
                                std::to_string(corners.size()));
  if (tetrahedron_contains(a, corners) || tetrahedron_contains(b, corners)) return 0;
  const auto face = [&](int i, int j, int k) { return segment_triangle_distance(a, b, corners[i], corners[j], corners[k]); };
  return std::min({face(1, 2, 3), face(0, 2, 3), face(0, 1, 3), face(0, 1, 2)});
}

}  // namespace snede
