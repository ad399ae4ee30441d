#include "needle/deformed_queries.hpp"

#include <algorithm>
#include <cmath>

namespace snede {
namespace {

double cross(const Point2& a, const Point2& b) { return a[0] * b[1] - a[1] * b[0]; }
Point2 minus(const Point2& a, const Point2& b) { return {a[0] - b[0], a[1] - b[1]}; }

}  // namespace

Point2 deformed_point(const Mesh& mesh, std::span<const double> u, VertexId v) {
  const auto X = mesh.point(v);
  const std::size_t i = static_cast<std::size_t>(v) * 2;
  return {X[0] + u[i], X[1] + u[i + 1]};
}

std::optional<Point2> reference_position(const Mesh& mesh, std::span<const double> u, const Point2& x) {
  const Connectivity& c = mesh.connectivity();
  double best = -1e-12;  // the most interior containing triangle wins (x on an edge: either)
  std::optional<Point2> found;
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    const Simplex& t = c.element(e).simplex;
    const Point2 p0 = deformed_point(mesh, u, t.vertex(0)), p1 = deformed_point(mesh, u, t.vertex(1)),
                 p2 = deformed_point(mesh, u, t.vertex(2));
    const double area = cross(minus(p1, p0), minus(p2, p0));
    if (area == 0) continue;
    const double l1 = cross(minus(x, p0), minus(p2, p0)) / area;
    const double l2 = cross(minus(p1, p0), minus(x, p0)) / area;
    const double l0 = 1 - l1 - l2;
    const double smallest = std::min({l0, l1, l2});
    if (smallest < best) continue;
    best = smallest;
    const auto X0 = mesh.point(t.vertex(0)), X1 = mesh.point(t.vertex(1)), X2 = mesh.point(t.vertex(2));
    found = Point2{l0 * X0[0] + l1 * X1[0] + l2 * X2[0], l0 * X0[1] + l1 * X1[1] + l2 * X2[1]};
  }
  return found;
}

std::vector<ShaftCrossing> shaft_crossings(const Mesh& mesh, std::span<const double> u, const Point2& a,
                                           const Point2& b) {
  std::vector<ShaftCrossing> crossings;
  const Point2 ab = minus(b, a);
  const double length = std::hypot(ab[0], ab[1]);
  if (length == 0) return crossings;
  const Point2 lo{std::min(a[0], b[0]), std::min(a[1], b[1])}, hi{std::max(a[0], b[0]), std::max(a[1], b[1])};
  const Connectivity& c = mesh.connectivity();
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    for (int j = 0; j < 3; ++j) {
      const FaceId f = c.element(e).faces[j];
      const Face& face = c.face(f);
      if (face.mate != no_id && face.mate < f) continue;  // each interior edge once
      const VertexId vp = face.simplex.vertex(0), vq = face.simplex.vertex(1);
      const Point2 p = deformed_point(mesh, u, vp), q = deformed_point(mesh, u, vq);
      if (std::max(p[0], q[0]) < lo[0] || std::min(p[0], q[0]) > hi[0] || std::max(p[1], q[1]) < lo[1] ||
          std::min(p[1], q[1]) > hi[1])
        continue;
      const double dp = cross(ab, minus(p, a)), dq = cross(ab, minus(q, a));
      if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || (dp == 0 && dq == 0)) continue;
      const Point2 pq = minus(q, p);
      const double da = cross(pq, minus(a, p)), db = cross(pq, minus(b, p));
      if ((da > 0 && db > 0) || (da < 0 && db < 0)) continue;
      const double t = da / (da - db);  // da ≠ db: the edge is not parallel to the segment
      const bool p_nearer = std::abs(dp) < std::abs(dq) || (std::abs(dp) == std::abs(dq) && vp < vq);
      crossings.push_back({p_nearer ? vp : vq, p_nearer ? vq : vp, t * length, face.mate == no_id});
    }
  }
  return crossings;
}

}  // namespace snede
