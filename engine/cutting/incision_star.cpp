#include "cutting/incision_star.hpp"

#include <algorithm>

#include "topology/local_star.hpp"

namespace snede {

std::vector<Wedge> star_wedges(const Connectivity& c, VertexId b) {
  std::vector<Wedge> result;
  for (ElementId e : local_star(c, b).elements) {
    const auto t = c.element(e).simplex.oriented_vertices();
    const int i = static_cast<int>(std::find(t.begin(), t.begin() + 3, b) - t.begin());
    result.push_back({e, t[(i + 1) % 3], t[(i + 2) % 3]});
  }
  return result;
}

bool is_boundary_edge(const Connectivity& c, ElementId triangle, VertexId opposite) {
  return c.face(c.opposite_face(triangle, opposite)).mate == no_id;
}

bool touches_boundary(const Connectivity& c, VertexId v) {
  for (ElementId e : local_star(c, v).elements)
    for (VertexId w : c.element(e).simplex.vertices())
      if (w != v && is_boundary_edge(c, e, w)) return true;
  return false;
}

std::vector<VertexId> lip_edges(const Connectivity& c, const std::unordered_set<VertexId>& incision_vertices) {
  std::vector<VertexId> edges;
  for (const auto& [simplex, f] : c.boundary()) {
    const auto v = simplex.oriented_vertices();
    if (incision_vertices.count(v[0]) && incision_vertices.count(v[1])) edges.insert(edges.end(), {v[0], v[1]});
  }
  return edges;
}

}  // namespace snede
