#include "problem/vertex_neighbours.hpp"

#include <algorithm>

#include "mesh/traversal.hpp"

namespace snede {

VertexNeighbours vertex_neighbours(const Connectivity& c, VertexId n, int corners, bool two_edges,
                                   std::span<const std::int64_t> order) {
  const VertexStars stars = all_vertex_stars(c, n);
  auto add_star = [&](VertexId v, auto&& add) {
    for (std::size_t s = stars.start[v]; s < stars.start[v + 1]; ++s)
      for (VertexId w : std::span(stars.vertices[stars.element_of(stars.entries[s])]).first(corners)) add(w);
  };
  VertexNeighbours found;
  found.start.assign(static_cast<std::size_t>(n) + 1, 0);
  found.neighbours.reserve(stars.entries.size() * 2 + n);
  if (!two_edges) found.block_rank.assign(static_cast<std::size_t>(c.element_capacity()) * corners * corners, 0);
  found.self_rank.resize(n);
  std::vector<VertexId>& neighbours = found.neighbours;
  std::vector<std::int32_t> place(n, -1);
  for (VertexId v = 0; v < n; ++v) {
    const std::size_t first = neighbours.size();
    neighbours.push_back(v);
    place[v] = 0;
    auto add = [&](VertexId w) {
      if (place[w] < 0) {
        place[w] = 0;
        neighbours.push_back(w);
      }
    };
    add_star(v, add);
    if (two_edges)
      for (std::size_t k = first + 1, end = neighbours.size(); k < end; ++k) add_star(neighbours[k], add);
    const auto row = neighbours.begin() + static_cast<std::ptrdiff_t>(first);
    if (order.empty()) {
      std::sort(row, neighbours.end());
    } else {
      std::sort(row, neighbours.end(), [&](VertexId a, VertexId b) { return order[a] < order[b]; });
    }
    for (std::size_t k = first; k < neighbours.size(); ++k) place[neighbours[k]] = static_cast<std::int32_t>(k - first);
    found.self_rank[v] = place[v];
    for (std::size_t s = stars.start[v]; s < stars.start[v + 1] && !two_edges; ++s) {
      const std::size_t k = stars.element_of(stars.entries[s]);
      const int a = stars.corner_of(stars.entries[s]);
      std::int32_t* ranks = found.block_rank.data() + (static_cast<std::size_t>(stars.elements[k]) * corners + a) * corners;
      for (int b = 0; b < corners; ++b) ranks[b] = place[stars.vertices[k][b]];
    }
    for (std::size_t k = first; k < neighbours.size(); ++k) place[neighbours[k]] = -1;
    found.start[v + 1] = neighbours.size();
  }
  return found;
}

}  // namespace snede
