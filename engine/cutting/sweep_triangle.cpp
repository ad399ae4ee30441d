#include "cutting/sweep_triangle.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/predicates.hpp"

namespace snede {
namespace {

// Whether the closed segment pq meets the closed triangle abc (exact unless coplanar, where
// bounding boxes decide: a generous answer only widens the search).
bool segment_meets_triangle(const Point3& p, const Point3& q, const Point3& a, const Point3& b, const Point3& c) {
  const int sp = orientation_3d(a.data(), b.data(), c.data(), p.data());
  const int sq = orientation_3d(a.data(), b.data(), c.data(), q.data());
  if (sp != 0 && sp == sq) return false;
  if (sp == 0 && sq == 0) {
    for (int k = 0; k < 3; ++k) {
      const double lo = std::min({a[k], b[k], c[k]}), hi = std::max({a[k], b[k], c[k]});
      if (std::max(p[k], q[k]) < lo || std::min(p[k], q[k]) > hi) return false;
    }
    return true;
  }
  const int o1 = orientation_3d(p.data(), q.data(), a.data(), b.data());
  const int o2 = orientation_3d(p.data(), q.data(), b.data(), c.data());
  const int o3 = orientation_3d(p.data(), q.data(), c.data(), a.data());
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

}  // namespace

SweepTriangle::SweepTriangle(std::span<const double> corners) {
  if (corners.size() != 9)
    throw std::invalid_argument("sweep triangle: expected (3, 3) corner coordinates, got " +
                                std::to_string(corners.size()) + " numbers");
  require_finite_points(corners.data(), corners.size(), 3, "sweep triangle", "corner");
  for (int i = 0; i < 3; ++i) corner_[i] = {corners[3 * i], corners[3 * i + 1], corners[3 * i + 2]};
  if (collinear_3d(corner_[0].data(), corner_[1].data(), corner_[2].data()))
    throw std::invalid_argument("sweep triangle: the three corners are collinear (the scalpel did not sweep an area)");
  const Point3 n = cross(minus(corner_[1], corner_[0]), minus(corner_[2], corner_[0]));
  const double length = std::sqrt(dot(n, n));
  if (!(length > 0) || !std::isfinite(length))
    throw std::invalid_argument("sweep triangle: its normal cannot be computed in double precision");
  normal_ = {n[0] / length, n[1] / length, n[2] / length};
  offset_ = dot(normal_, corner_[0]);
  for (int k = 0; k < 3; ++k) {
    lo_[k] = std::min({corner_[0][k], corner_[1][k], corner_[2][k]});
    hi_[k] = std::max({corner_[0][k], corner_[1][k], corner_[2][k]});
  }
}

double SweepTriangle::signed_distance(const Point3& x) const { return dot(normal_, x) - offset_; }

Point3 SweepTriangle::project(const Point3& x) const {
  const double d = signed_distance(x);
  return {x[0] - d * normal_[0], x[1] - d * normal_[1], x[2] - d * normal_[2]};
}

std::optional<double> SweepTriangle::crossing(const Point3& p, const Point3& q) const {
  const Point3 &a = corner_[0], &b = corner_[1], &c = corner_[2];
  const int sp = orientation_3d(a.data(), b.data(), c.data(), p.data());
  const int sq = orientation_3d(a.data(), b.data(), c.data(), q.data());
  if (sp == sq) return std::nullopt;  // same side, or both in the plane
  const int o1 = orientation_3d(p.data(), q.data(), a.data(), b.data());
  const int o2 = orientation_3d(p.data(), q.data(), b.data(), c.data());
  const int o3 = orientation_3d(p.data(), q.data(), c.data(), a.data());
  if (!((o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0))) return std::nullopt;
  if (sp == 0) return 0.0;
  if (sq == 0) return 1.0;
  const double dp = signed_distance(p), dq = signed_distance(q);
  return std::clamp(dp / (dp - dq), 0.0, 1.0);
}

bool SweepTriangle::box_overlaps(const Point3& lo, const Point3& hi) const {
  for (int k = 0; k < 3; ++k)
    if (hi[k] < lo_[k] || lo[k] > hi_[k]) return false;
  return true;
}

bool SweepTriangle::meets_triangle(const Point3& a, const Point3& b, const Point3& c) const {
  const Point3 &p = corner_[0], &q = corner_[1], &r = corner_[2];
  return segment_meets_triangle(a, b, p, q, r) || segment_meets_triangle(b, c, p, q, r) ||
         segment_meets_triangle(c, a, p, q, r) || segment_meets_triangle(p, q, a, b, c) ||
         segment_meets_triangle(q, r, a, b, c) || segment_meets_triangle(r, p, a, b, c);
}

bool SweepTriangle::meets_tetrahedron(const std::array<Point3, 4>& x) const {
  Point3 lo = x[0], hi = x[0];
  for (const Point3& p : x)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  if (!box_overlaps(lo, hi)) return false;
  // A corner of Δ inside the tetrahedron: on the inner side of (or on) all four faces.
  const int sign = orientation_3d(x[0].data(), x[1].data(), x[2].data(), x[3].data());
  auto inside = [&](const Point3& p) {
    return sign * orientation_3d(p.data(), x[1].data(), x[2].data(), x[3].data()) >= 0 &&
           sign * orientation_3d(x[0].data(), p.data(), x[2].data(), x[3].data()) >= 0 &&
           sign * orientation_3d(x[0].data(), x[1].data(), p.data(), x[3].data()) >= 0 &&
           sign * orientation_3d(x[0].data(), x[1].data(), x[2].data(), p.data()) >= 0;
  };
  if (sign != 0 && inside(corner_[0])) return true;
  // Otherwise Δ meets the tetrahedron's surface: one of its faces.
  return meets_triangle(x[1], x[2], x[3]) || meets_triangle(x[0], x[2], x[3]) || meets_triangle(x[0], x[1], x[3]) ||
         meets_triangle(x[0], x[1], x[2]);
}

}  // namespace snede
