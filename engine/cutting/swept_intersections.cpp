#include "cutting/swept_intersections.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/predicates.hpp"
#include "core/segment_distance.hpp"

namespace snede {

double segment_point_distance(const Point3& p, const Point3& q, const Point3& x) {
  return segment_segment_distance(p, q, x, x);
}

std::optional<TriangleHit> segment_meets_triangle(const Point3& p, const Point3& q, const Point3& a, const Point3& b,
                                                  const Point3& c, const Point3& near) {
  if (collinear_3d(a.data(), b.data(), c.data())) return std::nullopt;
  const int side_p = orientation_3d(a.data(), b.data(), c.data(), p.data());
  const int side_q = orientation_3d(a.data(), b.data(), c.data(), q.data());
  const Point3 normal = cross(minus(b, a), minus(c, a));
  const double doubled_area = dot(normal, normal);
  const auto weights_of = [&](const Point3& x) {
    return std::array<double, 3>{dot(cross(minus(b, x), minus(c, x)), normal) / doubled_area,
                                 dot(cross(minus(c, x), minus(a, x)), normal) / doubled_area,
                                 dot(cross(minus(a, x), minus(b, x)), normal) / doubled_area};
  };
  if (side_p == 0 && side_q == 0) {
    // Flat on the plane: clip the segment by the three sides (each a linear constraint in the
    // fraction along it), then take the point of the remaining piece nearest `near`.
    double low = 0, high = 1;
    const std::array<Point3, 3> corners{a, b, c};
    for (int k = 0; k < 3; ++k) {
      const Point3& from = corners[k];
      const Point3 side = cross(normal, minus(corners[(k + 1) % 3], from));  // points inwards
      const double at_p = dot(side, minus(p, from)), rate = dot(side, minus(q, p));
      if (rate == 0) {
        if (at_p < 0) return std::nullopt;
      } else if (rate > 0) {
        low = std::max(low, -at_p / rate);
      } else {
        high = std::min(high, -at_p / rate);
      }
    }
    if (low > high) return std::nullopt;
    const Point3 d = minus(q, p);
    const double length2 = dot(d, d);
    const double along = length2 > 0 ? std::clamp(dot(minus(near, p), d) / length2, low, high) : low;
    auto weights = weights_of(lerp(p, q, along));
    for (double& w : weights) w = std::max(w, 0.0);
    const double sum = weights[0] + weights[1] + weights[2];
    for (double& w : weights) w /= sum;
    return TriangleHit{weights, along};
  }
  if (side_p * side_q > 0) return std::nullopt;
  // The line p→q passes through the closed triangle: its sides are all on one side of it.
  const int ab = orientation_3d(p.data(), q.data(), a.data(), b.data());
  const int bc = orientation_3d(p.data(), q.data(), b.data(), c.data());
  const int ca = orientation_3d(p.data(), q.data(), c.data(), a.data());
  if ((ab < 0 || bc < 0 || ca < 0) && (ab > 0 || bc > 0 || ca > 0)) return std::nullopt;
  const double height_p = dot(normal, minus(p, a)), height_q = dot(normal, minus(q, a));
  const double along = height_p == height_q ? 0.0 : std::clamp(height_p / (height_p - height_q), 0.0, 1.0);
  auto weights = weights_of(lerp(p, q, along));
  // The exact signs say which sides the hit is on; zero weights where it is on a side.
  const std::array<int, 3> opposite{bc, ca, ab};
  for (int k = 0; k < 3; ++k) weights[k] = opposite[k] == 0 ? 0.0 : std::max(weights[k], 0.0);
  const double sum = weights[0] + weights[1] + weights[2];
  if (!(sum > 0)) return std::nullopt;
  for (double& w : weights) w /= sum;
  return TriangleHit{weights, along};
}

// The roots in [0, 1] (with rounding slack) of the quadratic through (0, f0), (½, half),
// (1, f1), smallest first; nothing when it vanishes identically (within `negligible`).
std::vector<double> quadratic_roots(double f0, double half, double f1, double negligible) {
  const double A = 2 * f1 - 4 * half + 2 * f0, B = f1 - f0 - A, C = f0;
  std::vector<double> roots;
  if (std::abs(A) <= negligible) {
    if (std::abs(B) > negligible) roots.push_back(-C / B);
  } else {
    const double discriminant = B * B - 4 * A * C;
    if (discriminant >= 0) {
      // The numerically stable pair of roots.
      const double q = -0.5 * (B + std::copysign(std::sqrt(discriminant), B));
      roots.push_back(q / A);
      if (q != 0) roots.push_back(C / q);
    } else if (discriminant > -1e-12 * B * B) {
      roots.push_back(-B / (2 * A));  // a double root lost to rounding: a grazing contact
    }
  }
  std::erase_if(roots, [](double g) { return g < -1e-12 || g > 1 + 1e-12; });
  for (double& g : roots) g = std::clamp(g, 0.0, 1.0);
  std::sort(roots.begin(), roots.end());
  return roots;
}

std::optional<SweptCrossing> swept_segment_meets_edge(const Point3& h0, const Point3& t0, const Point3& h1,
                                                      const Point3& t1, const Point3& a, const Point3& b) {
  const auto head = [&](double g) { return lerp(h0, h1, g); };
  const auto tail = [&](double g) { return lerp(t0, t1, g); };
  const double scale = std::max({norm(minus(t0, h0)), norm(minus(t1, h1)), norm(minus(b, a)), norm(minus(h1, h0)),
                                 norm(minus(t1, t0)), norm(minus(a, h0))});
  const double tolerance = 1e-9 * scale;
  const auto meeting = [&](double g) -> std::optional<SweptCrossing> {
    const ClosestPoints closest = segment_closest_points(head(g), tail(g), a, b);
    if (closest.distance > tolerance) return std::nullopt;
    return SweptCrossing{g, closest.s, closest.t};
  };
  const auto first_meeting = [&](const std::vector<double>& times) {
    std::optional<SweptCrossing> first;
    for (double g : times)
      if (auto hit = meeting(g); hit && (!first || hit->time < first->time)) first = hit;
    return first;
  };
  // (5.1): the scalpel's line and the edge's are coplanar where
  // f(γ) = (t(γ) − h(γ)) · ((a − h(γ)) × (b − a)) vanishes, a quadratic in γ.
  const auto f = [&](double g) { return dot(minus(tail(g), head(g)), cross(minus(a, head(g)), minus(b, a))); };
  const double negligible = 1e-12 * scale * scale * scale;
  const bool coplanar_throughout =
      orientation_3d(h0.data(), t0.data(), a.data(), b.data()) == 0 &&
      orientation_3d(h1.data(), t1.data(), a.data(), b.data()) == 0 && std::abs(f(0.5)) <= negligible;
  if (!coplanar_throughout) return first_meeting(quadratic_roots(f(0), f(0.5), f(1), negligible));
  // Flat in one plane throughout (the scalpel moving flat on a flat surface): two segments in
  // a plane first meet at the start, or when an end of one touches the other: an end of the
  // scalpel crosses the edge's line (linear in γ), or the scalpel's line sweeps over an end of
  // the edge (quadratic in γ). Signed areas are measured against the plane's normal.
  Point3 normal{0, 0, 0};
  for (const Point3& n : {cross(minus(t0, h0), minus(b, a)), cross(minus(t1, h1), minus(b, a)),
                          cross(minus(h1, h0), minus(b, a)), cross(minus(t0, h0), minus(h1, h0))})
    if (dot(n, n) > dot(normal, normal)) normal = n;
  std::vector<double> times{0.0};
  if (dot(normal, normal) <= negligible * negligible) {
    // Everything on one line: contact begins where an end of one segment reaches the other.
    for (int k = 0; k <= 64; ++k) times.push_back(k / 64.0);
    return first_meeting(times);
  }
  const auto area = [&](const Point3& x, const Point3& y, const Point3& z) { return dot(cross(minus(y, x), minus(z, x)), normal); };
  for (const auto& [p0, p1] : {std::pair{h0, h1}, std::pair{t0, t1}}) {
    const double d0 = area(a, b, p0), d1 = area(a, b, p1);
    if (d0 != d1) times.push_back(d0 / (d0 - d1));
  }
  for (const Point3& end : {a, b}) {
    const auto g = [&](double s) { return area(head(s), tail(s), end); };
    for (double root : quadratic_roots(g(0), g(0.5), g(1), negligible)) times.push_back(root);
  }
  std::erase_if(times, [](double g) { return !(g >= 0 && g <= 1); });
  return first_meeting(times);
}

double line_distance(const Point3& p, const Point3& q, const Point3& a, const Point3& b) {
  const Point3 n = cross(minus(q, p), minus(b, a));
  const double length = norm(n);
  if (length <= 1e-12 * norm(minus(q, p)) * norm(minus(b, a))) return segment_closest_points(p, q, a, b).distance;
  return std::abs(dot(minus(a, p), n)) / length;
}

}  // namespace snede
