#include "topology/local_star.hpp"

#include <stdexcept>
#include <string>

#include "mesh/traversal.hpp"

namespace snede {

LocalStar local_star(const Connectivity& c, VertexId v) {
  const ElementId start = c.vertex_element(v);
  if (start == no_id) return {};
  LocalStar star{vertex_star(c, v, start), true};
  if (star.elements.size() != static_cast<std::size_t>(c.n_vertex_uses(v))) {
    star.elements = vertex_star(c, v);
    star.face_connected = false;
  }
  return star;
}

std::vector<ElementId> elements_with_edge(const Connectivity& c, VertexId a, VertexId b) {
  std::vector<ElementId> around;
  for (ElementId e : local_star(c, a).elements)
    if (c.element(e).simplex.contains(b)) around.push_back(e);
  return around;
}

VertexId third_vertex(const Simplex& triangle, VertexId a, VertexId b) {
  for (VertexId v : triangle.vertices())
    if (v != a && v != b) return v;
  throw std::logic_error("third_vertex: triangle " + triangle.to_string() + " has no vertex besides " +
                         std::to_string(a) + " and " + std::to_string(b));
}

}  // namespace snede
