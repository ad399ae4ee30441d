#include "topology/flip_edge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <stdexcept>

#include "core/predicates.hpp"
#include "topology/local_star.hpp"
#include "topology/triangle_checks.hpp"

namespace snede {

namespace {

// The two triangles of an interior edge: left = (a, b, c), right = (b, a, d), both positive.
struct EdgeWings {
  ElementId left, right;
  VertexId c, d;
};

// The wings of (a, b), or the reason there are none.
std::optional<EdgeWings> edge_wings(const Mesh& mesh, VertexId a, VertexId b, std::string& why_not) {
  // Part of a refusal message, built only when one is given.
  const auto edge = [&] { return "edge " + vertex_list({a, b}); };
  if (a == b || !mesh.is_vertex(a) || !mesh.is_vertex(b)) {
    why_not = edge() + " does not exist: " + (a == b ? "its ends coincide" : "an end is not a vertex of the mesh");
    return std::nullopt;
  }
  const std::vector<ElementId> sharing = elements_with_edge(mesh.connectivity(), a, b);
  if (sharing.size() != 2) {
    why_not = edge() + (sharing.empty() ? " does not exist in the mesh" : " lies on the boundary");
    return std::nullopt;
  }
  const Connectivity& c = mesh.connectivity();
  EdgeWings wings{sharing[0], sharing[1], third_vertex(c.element(sharing[0]).simplex, a, b),
                  third_vertex(c.element(sharing[1]).simplex, a, b)};
  if (c.element(wings.left).simplex != Simplex(1, {a, b, wings.c})) {
    std::swap(wings.left, wings.right);
    std::swap(wings.c, wings.d);
  }
  return wings;
}

}  // namespace

EditResult flip_edge(Mesh& mesh, VertexId a, VertexId b) {
  if (mesh.cell_dim() != 2)
    throw std::invalid_argument("flip_edge: needs a triangle mesh (2D or surface), not a tetrahedral mesh");
  std::string why_not;
  const std::optional<EdgeWings> wings = edge_wings(mesh, a, b, why_not);
  if (!wings) return EditResult::refused("flip_edge: " + why_not);
  const VertexId c = wings->c, d = wings->d;
  // Part of a refusal message, built only when one is given.
  const auto flip = [&] { return "flip_edge: flipping " + vertex_list({a, b}) + " to " + vertex_list({c, d}); };
  if (c == d) return EditResult::refused(flip() + ": both triangles have the same corners");
  if (has_edge(mesh.connectivity(), c, d))
    return EditResult::refused(flip() + ": edge " + vertex_list({c, d}) +
                               " already exists, the flip would duplicate it (Figure 5.9)");
  const std::array<VertexId, 4> quadrilateral{a, d, b, c};
  const RetriangulationPlane plane(mesh, quadrilateral);
  if (!plane.has_normal()) return EditResult::refused(flip() + ": the quadrilateral has no area");
  for (const auto& [x, y, z] : {std::array<VertexId, 3>{a, d, c}, std::array<VertexId, 3>{b, c, d}}) {
    const std::string problem = plane.triangle_problem(x, y, z);
    if (!problem.empty()) {
      const std::string convexity = mesh.is_surface() ? "" : " (quadrilateral " + vertex_list({a, d, b, c}) + " is not strictly convex)";
      return EditResult::refused(flip() + ": " + problem + convexity);
    }
  }
  if (mesh.is_surface()) {
    // §5.3.1: on a surface the new triangles must also face the way both old ones did.
    const std::array<std::array<double, 3>, 2> old_normals{doubled_vector_area(mesh, a, b, c),
                                                           doubled_vector_area(mesh, b, a, d)};
    for (const auto& [x, y, z] : {std::array<VertexId, 3>{a, d, c}, std::array<VertexId, 3>{b, c, d}}) {
      const std::array<double, 3> normal = doubled_vector_area(mesh, x, y, z);
      for (const auto& old : old_normals)
        if (!(normal[0] * old[0] + normal[1] * old[1] + normal[2] * old[2] > 0))
          return EditResult::refused(flip() + ": triangle " + vertex_list({x, y, z}) +
                                     " would fold over (its normal points against an old triangle's)");
    }
  }
  const std::array<ElementId, 2> old_triangles{wings->left, wings->right};
  const std::array<Simplex, 2> new_triangles{Simplex(1, {a, d, c}), Simplex(1, {b, c, d})};
  mesh.connectivity().replace_elements(old_triangles, new_triangles);
  return EditResult::success();
}

namespace {

void require_triangles(const Mesh& mesh) {
  if (mesh.cell_dim() != 2) throw std::invalid_argument("is_locally_delaunay: needs a triangle mesh (2D or surface)");
}

// Interior angle at w of triangle (w, a, b) in 3D.
double angle_at(std::span<const double> w, std::span<const double> a, std::span<const double> b) {
  const std::array<double, 3> u{a[0] - w[0], a[1] - w[1], a[2] - w[2]}, v{b[0] - w[0], b[1] - w[1], b[2] - w[2]};
  const std::array<double, 3> n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return std::atan2(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), u[0] * v[0] + u[1] * v[1] + u[2] * v[2]);
}

// §5.3.1: the 2D criterion on a surface, the triangles (p, q, r) and (q, p, s) unfolded.
bool is_locally_delaunay_unfolded(const Mesh& mesh, VertexId p, VertexId q, VertexId r, VertexId s) {
  const auto P = mesh.point(p), Q = mesh.point(q), R = mesh.point(r), S = mesh.point(s);
  if (orientation_3d(P.data(), Q.data(), R.data(), S.data()) == 0) {
    // Coplanar: drop the coordinate along which the normal of (p, q, r) is largest; the
    // projection keeps (p, q, r) counter-clockwise when that normal component is positive.
    const auto n = doubled_vector_area(mesh, p, q, r);
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(n[k]) > std::abs(n[axis])) axis = k;
    const auto project = [&](std::span<const double> x) {
      return std::array<double, 2>{x[(axis + 1) % 3], x[(axis + 2) % 3]};
    };
    const auto p2 = project(P), q2 = project(Q), r2 = project(R), s2 = project(S);
    const int inside = in_circle(p2.data(), q2.data(), r2.data(), s2.data());
    return (n[axis] > 0 ? inside : -inside) <= 0;
  }
  return angle_at(R, P, Q) + angle_at(S, P, Q) <= std::acos(-1.0) * (1 + 1e-12);
}

}  // namespace

bool is_locally_delaunay(const Mesh& mesh, VertexId a, VertexId b) {
  require_triangles(mesh);
  const bool ends_are_vertices = a != b && mesh.is_vertex(a) && mesh.is_vertex(b);
  const std::vector<ElementId> sharing = ends_are_vertices ? elements_with_edge(mesh.connectivity(), a, b) : std::vector<ElementId>{};
  if (sharing.empty()) throw std::invalid_argument("is_locally_delaunay: edge " + vertex_list({a, b}) + " does not exist");
  return is_locally_delaunay(mesh, sharing.front(), a, b);
}

bool is_locally_delaunay(const Mesh& mesh, ElementId triangle, VertexId a, VertexId b) {
  require_triangles(mesh);
  const Connectivity& c = mesh.connectivity();
  if (!c.is_element(triangle) || !c.element(triangle).simplex.contains(a) || !c.element(triangle).simplex.contains(b))
    throw std::invalid_argument("is_locally_delaunay: element " + std::to_string(triangle) + " is not a triangle with edge " +
                                vertex_list({a, b}));
  const Simplex& near = c.element(triangle).simplex;
  const VertexId r = third_vertex(near, a, b);
  const ElementId across = c.neighbor(triangle, near.index(r));
  if (across == no_id) return true;
  const VertexId s = third_vertex(c.element(across).simplex, a, b);
  // (p, q, r) counter-clockwise, as the triangle is positive.
  const auto t = near.oriented_vertices();
  const int k = static_cast<int>(std::find(t.begin(), t.begin() + 3, r) - t.begin());
  const VertexId p = t[(k + 1) % 3], q = t[(k + 2) % 3];
  if (mesh.is_surface()) return is_locally_delaunay_unfolded(mesh, p, q, r, s);
  return in_circle(mesh.point(p).data(), mesh.point(q).data(), mesh.point(r).data(), mesh.point(s).data()) <= 0;
}

}  // namespace snede
