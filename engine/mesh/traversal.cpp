#include "mesh/traversal.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <unordered_set>

namespace snede {
namespace {

// One direction of cycle-around (§7.2); returns true if it came back to `entry`.
bool walk_around(const Connectivity& c, FaceId entry, VertexId v, std::vector<ElementId>& ring) {
  FaceId f = entry;
  while (f != no_id) {
    const ElementId e = c.face(f).element;
    const FaceId exit = c.opposite_face(e, v);
    v = c.opposite_vertex(e, f);
    ring.push_back(e);
    f = c.face(exit).mate;
    if (f == entry) return true;
  }
  return false;
}

}  // namespace

std::vector<ElementId> cycle_around(const Connectivity& c, FaceId entry, int j) {
  if (!c.is_face(entry)) throw std::invalid_argument("cycle_around: face " + std::to_string(entry) + " does not exist");
  if (j < 0 || j >= c.dim())
    throw std::invalid_argument("cycle_around: j must be in 0.." + std::to_string(c.dim() - 1));
  std::vector<ElementId> ring;
  const VertexId v = c.face(entry).simplex.vertex(j);
  if (walk_around(c, entry, v, ring)) return ring;
  const FaceId back = c.face(entry).mate;
  if (back == no_id) return ring;
  std::vector<ElementId> other;
  walk_around(c, back, v, other);
  std::reverse(other.begin(), other.end());
  other.insert(other.end(), ring.begin(), ring.end());
  return other;
}

std::vector<ElementId> elements_around(const Connectivity& c, const Simplex& s, ElementId start) {
  if (!c.is_element(start) || !c.element(start).simplex.contains_all(s))
    throw std::invalid_argument("elements_around: element " + std::to_string(start) + " does not contain " +
                                s.to_string());
  // Stars are small: a linear search of what was found beats hashing (and its allocations)
  // until the star is large, when the hash set takes over.
  constexpr std::size_t linear_search_limit = 64;
  std::vector<ElementId> found{start};
  std::unordered_set<ElementId> seen;
  const auto first_visit = [&](ElementId e) {
    if (found.size() < linear_search_limit) {
      if (std::find(found.begin(), found.end(), e) != found.end()) return false;
      found.push_back(e);
      if (found.size() == linear_search_limit) seen.insert(found.begin(), found.end());
      return true;
    }
    if (!seen.insert(e).second) return false;
    found.push_back(e);
    return true;
  };
  for (std::size_t i = 0; i < found.size(); ++i) {
    const Element& element = c.element(found[i]);
    for (int j = 0; j <= c.dim(); ++j) {
      if (s.contains(element.simplex.vertex(j))) continue;  // this face does not contain s
      const ElementId next = c.neighbor(found[i], j);
      if (next != no_id) first_visit(next);
    }
  }
  return found;
}

std::vector<ElementId> vertex_star(const Connectivity& c, VertexId v, ElementId start) {
  if (start != no_id) return elements_around(c, Simplex(1, {v}), start);
  // No start: scan, which also finds the parts of a star that touch only at v (a "bowtie").
  std::vector<ElementId> star;
  for (ElementId e = 0; e < c.element_capacity(); ++e)
    if (c.is_element(e) && c.element(e).simplex.contains(v)) star.push_back(e);
  return star;
}

std::vector<FaceId> boundary_faces(const Connectivity& c) {
  std::vector<std::pair<Simplex, FaceId>> entries(c.boundary().begin(), c.boundary().end());
  std::sort(entries.begin(), entries.end());
  std::vector<FaceId> faces;
  faces.reserve(entries.size());
  for (const auto& entry : entries) faces.push_back(entry.second);
  return faces;
}

VertexStars all_vertex_stars(const Connectivity& c, VertexId n_points) {
  VertexStars stars;
  stars.elements = c.element_ids();
  stars.vertices.resize(stars.elements.size());
  stars.start.assign(static_cast<std::size_t>(n_points) + 1, 0);
  const int corners = c.dim() + 1;
  for (std::size_t k = 0; k < stars.elements.size(); ++k) {
    stars.vertices[k] = c.element(stars.elements[k]).simplex.oriented_vertices();
    for (int a = 0; a < corners; ++a) ++stars.start[stars.vertices[k][a] + 1];
  }
  std::partial_sum(stars.start.begin(), stars.start.end(), stars.start.begin());
  stars.entries.resize(stars.start.back());
  std::vector<std::size_t> fill(stars.start.begin(), stars.start.end() - 1);
  for (std::size_t k = 0; k < stars.elements.size(); ++k)
    for (int a = 0; a < corners; ++a)
      stars.entries[fill[stars.vertices[k][a]]++] = static_cast<std::uint32_t>(k << 2) | static_cast<std::uint32_t>(a);
  return stars;
}

std::pair<std::vector<int>, int> connected_components(const Connectivity& c) {
  std::vector<int> label(c.element_capacity(), no_id);
  int n_components = 0;
  std::vector<ElementId> stack;
  for (ElementId seed = 0; seed < c.element_capacity(); ++seed) {
    if (!c.is_element(seed) || label[seed] != no_id) continue;
    label[seed] = n_components;
    stack.push_back(seed);
    while (!stack.empty()) {
      const ElementId e = stack.back();
      stack.pop_back();
      for (int j = 0; j <= c.dim(); ++j) {
        const ElementId next = c.neighbor(e, j);
        if (next != no_id && label[next] == no_id) {
          label[next] = n_components;
          stack.push_back(next);
        }
      }
    }
    ++n_components;
  }
  return {label, n_components};
}

}  // namespace snede
