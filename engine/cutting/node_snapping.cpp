#include "cutting/node_snapping.hpp"

#include <Eigen/Dense>
#include <limits>
#include <optional>

#include "core/predicates.hpp"
#include "topology/local_star.hpp"
#include "topology/snap_vertex.hpp"

namespace snede {
namespace {

Eigen::Vector3d vec(const Point3& p) { return {p[0], p[1], p[2]}; }

// Barycentric coordinates tolerance: a point on a shared face or edge belongs to both sides.
constexpr double inside_tolerance = 1e-10;

// The closest point to `from` on the line where the sweep plane meets the plane of boundary
// face (a, b, c), if it lies in that face.
std::optional<Eigen::Vector3d> on_boundary_face(const SweepTriangle& plane, const Eigen::Vector3d& from,
                                                const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                const Eigen::Vector3d& c) {
  const Eigen::Vector3d n1 = vec(plane.normal());
  Eigen::Vector3d n2 = (b - a).cross(c - a);
  const double area2 = n2.norm();
  if (!(area2 > 0)) return std::nullopt;
  n2 /= area2;
  const double cosine = n1.dot(n2), det = 1 - cosine * cosine;
  if (det < 1e-12) return std::nullopt;  // the face is parallel to the sweep plane
  // y = from + α n1 + β n2 on both planes: the nearest point of their intersection line.
  const double r1 = plane.offset() - n1.dot(from), r2 = n2.dot(a) - n2.dot(from);
  const double alpha = (r1 - cosine * r2) / det, beta = (r2 - cosine * r1) / det;
  const Eigen::Vector3d y = from + alpha * n1 + beta * n2;
  // Inside the face: the sub-triangle areas against the face normal are all ≥ 0.
  const double wa = (b - y).cross(c - y).dot(n2), wb = (c - y).cross(a - y).dot(n2), wc = (a - y).cross(b - y).dot(n2);
  const double tolerance = -inside_tolerance * area2;
  if (wa < tolerance || wb < tolerance || wc < tolerance) return std::nullopt;
  return y;
}

}  // namespace

EditResult snap_to_sweep(Mesh& mesh, const DeformedPositions& x, VertexId v, const SweepTriangle& plane) {
  const Connectivity& c = mesh.connectivity();
  const std::vector<ElementId> star = local_star(c, v).elements;
  const Eigen::Vector3d from = vec(x(v));
  const std::string name = "vertex " + std::to_string(v);

  // Where v goes in deformed space.
  bool on_boundary = false;
  std::optional<Eigen::Vector3d> target;
  for (ElementId e : star)
    for (FaceId f : c.element(e).faces) {
      const Face& face = c.face(f);
      if (face.mate != no_id || !face.simplex.contains(v)) continue;
      on_boundary = true;
      const Simplex& s = face.simplex;
      const auto y = on_boundary_face(plane, from, vec(x(s.vertex(0))), vec(x(s.vertex(1))), vec(x(s.vertex(2))));
      if (y && (!target || (*y - from).norm() < (*target - from).norm())) target = y;
    }
  if (!on_boundary) target = vec(plane.project(x(v)));
  if (!target) return EditResult::refused(name + " is on the boundary and no boundary face around it meets the sweep plane");

  // The tetrahedron of the star containing it (deformed), and the point's barycentric
  // coordinates there: the most interior choice when it lies on a shared face.
  ElementId host = no_id;
  Eigen::Vector4d weights;
  double best = -std::numeric_limits<double>::infinity();
  for (ElementId e : star) {
    const std::array<Point3, 4> corners = x.corners(c.element(e).simplex);
    Eigen::Matrix3d edges;
    for (int k = 0; k < 3; ++k) edges.col(k) = vec(corners[k + 1]) - vec(corners[0]);
    const Eigen::Vector3d l = edges.fullPivLu().solve(*target - vec(corners[0]));
    const Eigen::Vector4d w(1 - l.sum(), l[0], l[1], l[2]);
    if (w.allFinite() && w.minCoeff() > best) best = w.minCoeff(), weights = w, host = e;
  }
  if (host == no_id || best < -inside_tolerance)
    return EditResult::refused(name + ": no tetrahedron around it contains its snapped position (deformed)");
  weights = weights.cwiseMax(0.0);
  weights /= weights.sum();
  const Simplex& tet = c.element(host).simplex;
  const std::array<VertexId, 4> parents{tet.vertex(0), tet.vertex(1), tet.vertex(2), tet.vertex(3)};
  const VertexParents snapped = VertexParents::barycentric(parents, std::span<const double>(weights.data(), 4));

  // The deformed star must stay positive with v at its new deformed position.
  Eigen::Vector3d moved = Eigen::Vector3d::Zero();
  for (int k = 0; k < 4; ++k) moved += weights[k] * vec(x(parents[k]));
  const Point3 at{moved[0], moved[1], moved[2]};
  for (ElementId e : star) {
    const std::array<VertexId, 4> order = c.element(e).simplex.oriented_vertices();
    std::array<Point3, 4> p;
    for (int k = 0; k < 4; ++k) p[k] = x(order[k]);
    if (orientation_3d(p[0].data(), p[1].data(), p[2].data(), p[3].data()) <= 0) continue;  // already inverted
    for (int k = 0; k < 4; ++k)
      if (order[k] == v) p[k] = at;
    if (orientation_3d(p[0].data(), p[1].data(), p[2].data(), p[3].data()) <= 0)
      return EditResult::refused(name + ": snapping would invert element " + std::to_string(e) + " in the deformed body");
  }
  return snap_vertex(mesh, v, snapped);
}

}  // namespace snede
