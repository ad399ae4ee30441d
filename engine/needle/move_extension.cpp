#include "needle/move_extension.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "mesh/traversal.hpp"

namespace snede {
namespace {

struct Neighbourhood {
  std::vector<VertexId> vertices;  // those sharing an element with v
  bool on_boundary = false;        // v is on a boundary face
};

Neighbourhood neighbourhood(const Connectivity& c, VertexId v) {
  Neighbourhood around;
  const ElementId start = c.vertex_element(v);
  if (start == no_id) return around;
  for (ElementId e : vertex_star(c, v, start)) {
    const Simplex& simplex = c.element(e).simplex;
    for (int j = 0; j < simplex.count(); ++j) {
      const VertexId w = simplex.vertex(j);
      if (w != v) {
        around.vertices.push_back(w);
        around.on_boundary = around.on_boundary || c.neighbor(e, j) == no_id;  // face j holds v
      }
    }
  }
  std::sort(around.vertices.begin(), around.vertices.end());
  around.vertices.erase(std::unique(around.vertices.begin(), around.vertices.end()), around.vertices.end());
  return around;
}

}  // namespace

std::vector<std::pair<VertexId, double>> move_extension_weights(const Mesh& mesh, const Constraints& constraints,
                                                                std::span<const VertexId> moved, int rings,
                                                                int sweeps) {
  if (rings < 0 || sweeps < 0)
    throw std::invalid_argument("move_extension_weights: rings and sweeps must be ≥ 0, got " + std::to_string(rings) +
                                " and " + std::to_string(sweeps));
  const Connectivity& c = mesh.connectivity();
  // Breadth-first rings: ring 0 is `moved`; ring[v] = -1 for vertices not reached.
  std::vector<int> ring(static_cast<std::size_t>(mesh.n_points()), -1);
  std::vector<VertexId> reached;
  std::vector<Neighbourhood> around;  // of reached[i]
  for (VertexId v : moved)
    if (ring[v] < 0) {
      ring[v] = 0;
      reached.push_back(v);
    }
  std::size_t first = 0;
  for (int r = 1; r <= rings + 1; ++r) {
    const std::size_t end = reached.size();
    for (std::size_t i = first; i < end; ++i) {
      around.push_back(neighbourhood(c, reached[i]));
      if (r > rings) continue;  // the last ring's neighbourhoods are for the sweeps only
      for (VertexId w : around.back().vertices)
        if (ring[w] < 0) {
          ring[w] = r;
          reached.push_back(w);
        }
    }
    first = end;
  }
  // Free and sliding (slipping needle nodes, which slide along the shaft) vertices inside the
  // body: the surface stays where the last solve left it, so that the nodes the update
  // intercepts, and the shaft's length inside the body that sets their thresholds, are found
  // on it. (Slipping nodes carried along avoid most inversions: on a gmsh liver, 24 halvings
  // over 30 mm without the extension, 16 with free vertices only, 3 with the slipping ones.)
  auto movable = [&](std::size_t i) {
    const ConstraintKind kind = constraints[reached[i]].kind;
    return ring[reached[i]] > 0 && (kind == ConstraintKind::free || kind == ConstraintKind::slide) &&
           !around[i].on_boundary;
  };
  std::vector<double> weight(reached.size());
  std::vector<std::size_t> index(static_cast<std::size_t>(mesh.n_points()), reached.size());
  for (std::size_t i = 0; i < reached.size(); ++i) {
    index[reached[i]] = i;
    const int r = ring[reached[i]];
    weight[i] = r == 0 ? 1.0 : movable(i) ? 1.0 - double(r) / (rings + 1) : 0.0;
  }
  std::vector<double> next = weight;
  for (int s = 0; s < sweeps; ++s) {
    for (std::size_t i = 0; i < reached.size(); ++i) {
      if (!movable(i) || around[i].vertices.empty()) continue;
      double sum = 0;
      for (VertexId w : around[i].vertices) sum += index[w] < reached.size() ? weight[index[w]] : 0.0;
      next[i] = sum / static_cast<double>(around[i].vertices.size());
    }
    weight.swap(next);
  }
  std::vector<std::pair<VertexId, double>> result;
  for (std::size_t i = 0; i < reached.size(); ++i)
    if (movable(i) && weight[i] > 0) result.emplace_back(reached[i], weight[i]);
  return result;
}

}  // namespace snede
