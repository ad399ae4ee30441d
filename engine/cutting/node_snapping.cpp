#include "cutting/node_snapping.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <optional>

#include "core/predicates.hpp"
#include "topology/local_star.hpp"
#include "topology/snap_vertex.hpp"

namespace snede {
namespace {

Eigen::Vector3d vec(const Point3& p) { return {p[0], p[1], p[2]}; }

// Barycentric coordinates tolerance: a point on a shared face or edge belongs to both sides.
constexpr double inside_tolerance = 1e-10;
// A snap may shrink an element of the body as it is now to no less than this fraction of its
// volume there.
constexpr double current_flattening_floor = 1e-3;

double signed_volume(const std::array<Point3, 4>& p) {
  Eigen::Matrix3d edges;
  for (int k = 0; k < 3; ++k) edges.col(k) = vec(p[k + 1]) - vec(p[0]);
  return edges.determinant() / 6.0;
}

// Candidates for a boundary vertex in boundary face `corner`: where the sweep plane crosses
// the face, a segment; its point closest to `from`, and its two ends (which lie on the face's
// edges, and so on a crease of the body when the face borders one).
std::vector<Eigen::Vector3d> on_boundary_face(const SweepTriangle& plane, const Eigen::Vector3d& from,
                                              const std::array<Eigen::Vector3d, 3>& corner) {
  std::array<double, 3> d;
  for (int k = 0; k < 3; ++k) d[k] = plane.signed_distance({corner[k][0], corner[k][1], corner[k][2]});
  std::vector<Eigen::Vector3d> ends;
  for (int k = 0; k < 3; ++k) {
    const int l = (k + 1) % 3;
    if (d[k] == 0) ends.push_back(corner[k]);
    if ((d[k] < 0 && d[l] > 0) || (d[k] > 0 && d[l] < 0)) ends.push_back(corner[k] + d[k] / (d[k] - d[l]) * (corner[l] - corner[k]));
  }
  if (ends.size() == 2) {
    const Eigen::Vector3d p = ends[0], pq = ends[1] - ends[0];
    const double length2 = pq.squaredNorm();
    if (length2 > 0) ends.push_back(p + std::clamp((from - p).dot(pq) / length2, 0.0, 1.0) * pq);
  }
  return ends;
}

Eigen::Vector3d unit_normal(const std::array<Eigen::Vector3d, 3>& face) {
  return (face[1] - face[0]).cross(face[2] - face[0]).normalized();
}

// Boundary faces meeting at more than this angle form a crease (an edge or corner of the body)
// that a snapped vertex must stay on; below it the surface counts as smooth.
constexpr double crease_angle_cosine = 0.866;  // 30°

}  // namespace

EditResult snap_to_sweep(Mesh& mesh, const DeformedPositions& x, VertexId v, const SweepTriangle& plane,
                         const DeformedPositions* current) {
  const Connectivity& c = mesh.connectivity();
  const std::vector<ElementId> star = local_star(c, v).elements;
  const Eigen::Vector3d from = vec(x(v));
  const std::string name = "vertex " + std::to_string(v);

  // Where v goes in deformed space.
  std::vector<std::array<Eigen::Vector3d, 3>> boundary;
  std::map<VertexId, std::vector<Eigen::Vector3d>> edge_normals;  // boundary edges (v, w): their faces' normals
  for (ElementId e : star)
    for (FaceId f : c.element(e).faces) {
      const Face& face = c.face(f);
      if (face.mate != no_id || !face.simplex.contains(v)) continue;
      const auto corner = face.simplex.oriented_vertices();  // consistent normals across faces
      boundary.push_back({vec(x(corner[0])), vec(x(corner[1])), vec(x(corner[2]))});
      for (VertexId w : face.simplex.vertices())
        if (w != v) edge_normals[w].push_back(unit_normal(boundary.back()));
    }
  std::vector<VertexId> creases;
  for (const auto& [w, normals] : edge_normals)
    if (normals.size() == 2 && normals[0].dot(normals[1]) < crease_angle_cosine) creases.push_back(w);
  auto consider = [&](const Eigen::Vector3d& y, std::optional<Eigen::Vector3d>& best) {
    if (!best || (y - from).norm() < (*best - from).norm()) best = y;
  };
  std::optional<Eigen::Vector3d> target;
  if (boundary.empty()) {
    target = vec(plane.project(x(v)));
  } else if (creases.empty()) {  // a smooth surface: anywhere the plane crosses a face around v
    for (const auto& face : boundary)
      for (const Eigen::Vector3d& y : on_boundary_face(plane, from, face)) consider(y, target);
  } else if (creases.size() == 2) {  // on an edge of the body: only along it, so the body keeps its shape
    for (VertexId w : creases) {
      const double dv = plane.signed_distance(x(v)), dw = plane.signed_distance(x(w));
      if ((dv <= 0 && dw >= 0) || (dv >= 0 && dw <= 0))
        if (dv != dw) consider(from + dv / (dv - dw) * (vec(x(w)) - from), target);
    }
  }  // a corner of the body does not move
  if (!target)
    return EditResult::refused(name + " is on the boundary: a corner, or the sweep plane crosses no boundary face (or edge of the body) around it");

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

  // The deformed star must stay positive with v at its new deformed position, in the
  // configuration the sweep is made against and in the body's current one. In the current one
  // it must not go nearly flat either: the reference configuration's degenerate elements are
  // removed after the sweep (§3.2), but one flat only as the body is now was not, and left
  // J ≈ 1e-13, a non-finite neo-Hookean stress and every later solve failing (organ_cuts: the
  // torus's failed solves after cuts).
  for (const DeformedPositions* config : {&x, current}) {
    if (!config) continue;
    Eigen::Vector3d moved = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) moved += weights[k] * vec((*config)(parents[k]));
    const Point3 at{moved[0], moved[1], moved[2]};
    for (ElementId e : star) {
      const std::array<VertexId, 4> order = c.element(e).simplex.oriented_vertices();
      std::array<Point3, 4> p;
      for (int k = 0; k < 4; ++k) p[k] = (*config)(order[k]);
      if (orientation_3d(p[0].data(), p[1].data(), p[2].data(), p[3].data()) <= 0) continue;  // already inverted
      const double before = signed_volume(p);
      for (int k = 0; k < 4; ++k)
        if (order[k] == v) p[k] = at;
      if (orientation_3d(p[0].data(), p[1].data(), p[2].data(), p[3].data()) <= 0)
        return EditResult::refused(name + ": snapping would invert element " + std::to_string(e) + " in the deformed body");
      if (config == current && signed_volume(p) < current_flattening_floor * before)
        return EditResult::refused(name + ": snapping would flatten element " + std::to_string(e) +
                                   " in the body as it is now");
    }
  }
  return snap_vertex(mesh, v, snapped);
}

}  // namespace snede
