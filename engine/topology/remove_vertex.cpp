#include "topology/remove_vertex.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "core/predicates.hpp"
#include "topology/local_star.hpp"
#include "topology/triangle_checks.hpp"

namespace snede {

namespace {

// The link of v as one polygon, counter-clockwise around v (the order of v's triangles
// (v, p_i, p_i+1)); `closed` for an interior vertex, open from p_0 to p_m on the boundary.
struct Link {
  std::vector<VertexId> polygon;
  bool closed = false;
};

std::optional<Link> link_of(const Mesh& mesh, VertexId v, const std::vector<ElementId>& star, std::string& why_not) {
  std::unordered_map<VertexId, VertexId> next;
  std::unordered_set<VertexId> targets;
  VertexId first_from = no_id;
  for (ElementId e : star) {
    const auto corners = mesh.connectivity().element(e).simplex.oriented_vertices();
    const int at = static_cast<int>(std::find(corners.begin(), corners.begin() + 3, v) - corners.begin());
    const VertexId from = corners[(at + 1) % 3], to = corners[(at + 2) % 3];
    if (e == star[0]) first_from = from;
    if (!next.emplace(from, to).second || !targets.insert(to).second) {
      why_not = "vertex " + std::to_string(from) + " or " + std::to_string(to) + " is twice in the link (non-manifold)";
      return std::nullopt;
    }
  }
  Link link;
  VertexId start = first_from;
  for (const auto& [from, to] : next)
    if (!targets.count(from)) start = from;
  link.closed = targets.count(start) > 0;
  for (VertexId p = start;;) {
    link.polygon.push_back(p);
    const auto found = next.find(p);
    if (found == next.end() || found->second == start) break;
    p = found->second;
  }
  const std::size_t expected = star.size() + (link.closed ? 0 : 1);
  if (link.polygon.size() != expected) {
    why_not = "its star is not one fan (non-manifold vertex)";
    return std::nullopt;
  }
  return link;
}

// True if v lies strictly between x and y on the segment joining them, given that the three
// are exactly collinear: the differences (exact in sign) point in opposite directions.
bool strictly_between(std::span<const double> x, std::span<const double> v, std::span<const double> y) {
  bool opposite = false;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const int to_x = (x[k] > v[k]) - (x[k] < v[k]), to_y = (y[k] > v[k]) - (y[k] < v[k]);
    if (to_x * to_y > 0) return false;
    opposite = opposite || to_x * to_y < 0;
  }
  return opposite;
}

// Why the caller's check or a watcher of the mesh (a body whose displacement it would invert,
// issue 48 item 7) refuses `triangle`, or empty.
std::string refusal(const Mesh& mesh, const TriangleCheck& acceptable, const Simplex& triangle) {
  const std::string vertices = vertex_list({triangle.vertex(0), triangle.vertex(1), triangle.vertex(2)});
  if (acceptable && !acceptable(triangle)) return "the caller refuses triangle " + vertices;
  if (std::string why = mesh.connectivity().watcher_refusal(triangle); !why.empty())
    return "triangle " + vertices + " " + why;
  return {};
}

// Ear clipping of `polygon` (counter-clockwise in `plane`): the triangles, or the reason the
// greedy choice got stuck.
std::optional<std::vector<Simplex>> ear_triangulation(const Mesh& mesh, const RetriangulationPlane& plane,
                                                      std::vector<VertexId> remaining, const TriangleCheck& acceptable,
                                                      std::string& why_not) {
  std::vector<Simplex> triangles;
  while (remaining.size() > 3) {
    const std::size_t n = remaining.size();
    std::optional<std::size_t> chosen;
    bool chosen_is_delaunay = false;
    std::string last_problem;
    for (std::size_t i = 0; i < n && !chosen_is_delaunay; ++i) {
      const VertexId previous = remaining[(i + n - 1) % n], tip = remaining[i], following = remaining[(i + 1) % n];
      std::string problem = plane.triangle_problem(previous, tip, following);
      bool delaunay = true;
      for (VertexId q : remaining) {
        if (!problem.empty() || q == previous || q == tip || q == following) continue;
        if (plane.closed_triangle_contains(previous, tip, following, q))
          problem = "triangle " + vertex_list({previous, tip, following}) + " would contain vertex " + std::to_string(q);
        delaunay = delaunay && !plane.in_circumcircle(previous, tip, following, q);
      }
      if (problem.empty() && has_edge(mesh.connectivity(), previous, following))
        problem = "edge " + vertex_list({previous, following}) + " already exists";
      if (problem.empty()) problem = refusal(mesh, acceptable, Simplex(1, {previous, tip, following}));
      if (!problem.empty()) {
        last_problem = problem;
        continue;
      }
      if (!chosen || delaunay) {
        chosen = i;
        chosen_is_delaunay = delaunay;
      }
    }
    if (!chosen) {
      why_not = "no valid ear among the " + std::to_string(n) + " remaining link vertices (last: " + last_problem + ")";
      return std::nullopt;
    }
    const std::size_t i = *chosen;
    triangles.push_back(Simplex(1, {remaining[(i + n - 1) % n], remaining[i], remaining[(i + 1) % n]}));
    remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(i));
  }
  std::string problem = plane.triangle_problem(remaining[0], remaining[1], remaining[2]);
  if (problem.empty()) problem = refusal(mesh, acceptable, Simplex(1, {remaining[0], remaining[1], remaining[2]}));
  if (!problem.empty()) {
    why_not = problem;
    return std::nullopt;
  }
  triangles.push_back(Simplex(1, {remaining[0], remaining[1], remaining[2]}));
  return triangles;
}

}  // namespace

EditResult remove_vertex_by_flips(Mesh& mesh, VertexId v, const TriangleCheck& acceptable) {
  if (mesh.cell_dim() != 2)
    throw std::invalid_argument("remove_vertex_by_flips: needs a triangle mesh (2D or surface), not a tetrahedral mesh");
  if (!mesh.is_vertex(v))
    throw std::invalid_argument("remove_vertex_by_flips: " + std::to_string(v) + " is not a vertex of the mesh");
  // Part of a refusal message, built only when one is given.
  const auto removing = [&] { return "remove_vertex_by_flips of vertex " + std::to_string(v) + ": "; };
  const std::vector<ElementId> star = local_star(mesh.connectivity(), v).elements;
  if (star.empty()) return EditResult::refused(removing() + "it is in no cell (Mesh::remove_vertex removes it)");
  std::string why_not;
  const std::optional<Link> link = link_of(mesh, v, star, why_not);
  if (!link) return EditResult::refused(removing() + why_not);
  const std::vector<VertexId>& polygon = link->polygon;
  if (!link->closed) {
    const VertexId first = polygon.front(), last = polygon.back();
    const auto x = mesh.point(last), y = mesh.point(first), at = mesh.point(v);
    const bool collinear = mesh.is_surface() ? collinear_3d(x.data(), at.data(), y.data())
                                             : orientation_2d(x.data(), at.data(), y.data()) == 0;
    if (!collinear || !strictly_between(x, at, y))
      return EditResult::refused(removing() + "a boundary vertex is removed only when it lies straight between its "
                                            "boundary neighbours, and " + vertex_list({last, v, first}) +
                                 " is not a straight segment");
    if (has_edge(mesh.connectivity(), last, first))
      return EditResult::refused(removing() + "the new boundary edge " + vertex_list({last, first}) + " already exists");
  }
  const RetriangulationPlane plane(mesh, polygon);
  if (!plane.has_normal()) return EditResult::refused(removing() + "its star has no area");
  const std::optional<std::vector<Simplex>> triangles = ear_triangulation(mesh, plane, polygon, acceptable, why_not);
  if (!triangles) return EditResult::refused(removing() + why_not);
  // A link of three vertices closes into one triangle; on a closed surface it may exist already.
  const Simplex& last_triangle = triangles->back();
  for (ElementId e : elements_with_edge(mesh.connectivity(), last_triangle.vertex(0), last_triangle.vertex(1)))
    if (mesh.connectivity().element(e).simplex.same_vertices(last_triangle))
      return EditResult::refused(removing() + "triangle " + last_triangle.to_string() + " already exists");

  ChangeBatch batch(mesh.connectivity());  // one change: the new triangles and the removed vertex
  mesh.connectivity().replace_elements(star, *triangles);
  mesh.remove_vertex(v);
  return EditResult::success();
}

}  // namespace snede
