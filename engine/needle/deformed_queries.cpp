#include "needle/deformed_queries.hpp"

#include <algorithm>
#include <cmath>

namespace snede {
namespace {

// The z component of a × b: the signed area in the plane.
double cross2(const Point& a, const Point& b) { return a[0] * b[1] - a[1] * b[0]; }
double triple(const Point& a, const Point& b, const Point& c) { return dot(a, cross(b, c)); }

// Distance from x to the line through a with unit direction t.
double line_distance(const Point& x, const Point& a, const Point& t) {
  const Point r = minus(x, a);
  const double along = dot(r, t);
  return std::sqrt(std::max(0.0, dot(r, r) - along * along));
}

bool boxes_miss(const std::vector<Point>& corners, const Point& lo, const Point& hi, int d) {
  for (int k = 0; k < d; ++k) {
    double mn = corners[0][k], mx = corners[0][k];
    for (const Point& p : corners) {
      mn = std::min(mn, p[k]);
      mx = std::max(mx, p[k]);
    }
    if (mx < lo[k] || mn > hi[k]) return true;
  }
  return false;
}

// Which side of the line through a along ab the point p is on (the signed area, × |ab|).
double side_of(const Point& a, const Point& ab, const Point& p) { return cross2(ab, minus(p, a)); }

// An edge whose ends are on one side of the line (sides dp, dq), or on it, does not cross it.
bool misses_line(double dp, double dq) { return (dp > 0 && dq > 0) || (dp < 0 && dq < 0) || (dp == 0 && dq == 0); }

// Edge p–q, its ends on sides dp, dq of the line, against segment a–b in the plane: the
// parameter along a→b, or none.
std::optional<double> crossing_2d(const Point& a, const Point& b, const Point& p, const Point& q, double dp,
                                  double dq) {
  if (misses_line(dp, dq)) return std::nullopt;
  const Point pq = minus(q, p);
  const double da = cross2(pq, minus(a, p)), db = cross2(pq, minus(b, p));
  if ((da > 0 && db > 0) || (da < 0 && db < 0)) return std::nullopt;
  return da / (da - db);  // da ≠ db: the edge is not parallel to the segment
}

// Triangle p, q, r against segment a–b in space (signed volumes): the parameter, or none. A
// segment in the triangle's plane does not cross it.
std::optional<double> crossing_3d(const Point& a, const Point& b, const Point& p, const Point& q, const Point& r) {
  const double va = triple(minus(q, p), minus(r, p), minus(a, p)), vb = triple(minus(q, p), minus(r, p), minus(b, p));
  if ((va > 0 && vb > 0) || (va < 0 && vb < 0) || va == vb) return std::nullopt;
  const Point ab = minus(b, a);
  const double s0 = triple(ab, minus(p, a), minus(q, a)), s1 = triple(ab, minus(q, a), minus(r, a)),
               s2 = triple(ab, minus(r, a), minus(p, a));
  if ((s0 < 0 || s1 < 0 || s2 < 0) && (s0 > 0 || s1 > 0 || s2 > 0)) return std::nullopt;  // passes beside it
  return va / (va - vb);
}

// x is beyond the triangle's bounding box by more than a millionth of its size: then one of
// its barycentric coordinates is far below reference_position's −1e-12, and the division
// that computes them is skipped.
bool outside_box(const Point& x, const Point& p0, const Point& p1, const Point& p2) {
  for (int k = 0; k < 2; ++k) {
    const double lo = std::min({p0[k], p1[k], p2[k]}), hi = std::max({p0[k], p1[k], p2[k]});
    const double margin = 1e-6 * (hi - lo);
    if (x[k] < lo - margin || x[k] > hi + margin) return true;
  }
  return false;
}

}  // namespace

std::optional<Point> reference_position(const Mesh& mesh, std::span<const double> u, const Point& x) {
  const Connectivity& c = mesh.connectivity();
  const int d = mesh.dim();
  const DeformedPositions deformed(mesh, u);
  double best = -1e-12;  // the most interior containing element wins (x on a face: either)
  std::optional<Point> found;
  std::array<double, 4> lambda{};
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    const Simplex& t = c.element(e).simplex;
    const Point p0 = deformed(t.vertex(0)), p1 = deformed(t.vertex(1)), p2 = deformed(t.vertex(2));
    if (d == 2 && outside_box(x, p0, p1, p2)) continue;
    if (d == 2) {
      const double area = cross2(minus(p1, p0), minus(p2, p0));
      if (area == 0) continue;
      lambda[1] = cross2(minus(x, p0), minus(p2, p0)) / area;
      lambda[2] = cross2(minus(p1, p0), minus(x, p0)) / area;
      lambda[0] = 1 - lambda[1] - lambda[2];
    } else {
      const Point p3 = deformed(t.vertex(3));
      const Point e1 = minus(p1, p0), e2 = minus(p2, p0), e3 = minus(p3, p0), r = minus(x, p0);
      const double volume = triple(e1, e2, e3);
      if (volume == 0) continue;
      lambda[1] = triple(r, e2, e3) / volume;
      lambda[2] = triple(e1, r, e3) / volume;
      lambda[3] = triple(e1, e2, r) / volume;
      lambda[0] = 1 - lambda[1] - lambda[2] - lambda[3];
    }
    const double smallest = *std::min_element(lambda.begin(), lambda.begin() + d + 1);
    if (smallest < best) continue;
    best = smallest;
    Point X{0, 0, 0};
    for (int i = 0; i <= d; ++i)
      for (int k = 0; k < d; ++k) X[k] += lambda[i] * mesh.point(t.vertex(i))[k];
    found = X;
  }
  return found;
}

std::vector<ShaftCrossing> shaft_crossings(const Mesh& mesh, std::span<const double> u, const Point& a,
                                           const Point& b) {
  std::vector<ShaftCrossing> crossings;
  const int d = mesh.dim();
  const Point ab = minus(b, a);
  const double length = std::sqrt(dot(ab, ab));
  if (length == 0) return crossings;
  const Point axis{ab[0] / length, ab[1] / length, ab[2] / length};
  Point lo{}, hi{};
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min(a[k], b[k]);
    hi[k] = std::max(a[k], b[k]);
  }
  const Connectivity& c = mesh.connectivity();
  const DeformedPositions deformed(mesh, u);
  // 2D: each vertex's side of the line, once (not once per edge): most edges have both ends
  // on one side and are passed over before their corners are looked at (issue 33).
  std::vector<double> side;
  if (d == 2) {
    side.resize(static_cast<std::size_t>(mesh.n_points()));
    for (VertexId v = 0; v < mesh.n_points(); ++v)
      if (mesh.is_vertex(v)) side[v] = side_of(a, ab, deformed(v));
  }
  std::vector<Point> corners(d);
  std::vector<VertexId> ids(d);
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    for (int j = 0; j <= d; ++j) {
      const FaceId f = c.element(e).faces[j];
      const Face& face = c.face(f);
      if (face.mate != no_id && face.mate < f) continue;  // each interior face once
      if (d == 2 && misses_line(side[face.simplex.vertex(0)], side[face.simplex.vertex(1)])) continue;
      for (int i = 0; i < d; ++i) {
        ids[i] = face.simplex.vertex(i);
        corners[i] = deformed(ids[i]);
      }
      if (boxes_miss(corners, lo, hi, d)) continue;
      const std::optional<double> t =
          d == 2 ? crossing_2d(a, b, corners[0], corners[1], side[ids[0]], side[ids[1]])
                 : crossing_3d(a, b, corners[0], corners[1], corners[2]);
      if (!t) continue;
      // The corner nearest the shaft's line (ties: the lower id, for determinism).
      int nearest = 0;
      double nearest_distance = line_distance(corners[0], a, axis);
      for (int i = 1; i < d; ++i) {
        const double distance = line_distance(corners[i], a, axis);
        if (distance < nearest_distance || (distance == nearest_distance && ids[i] < ids[nearest])) {
          nearest = i;
          nearest_distance = distance;
        }
      }
      crossings.push_back({ids[nearest], *t * length, face.mate == no_id});
    }
  }
  return crossings;
}

}  // namespace snede
