#include "mesh/vertex_parents.hpp"

#include <algorithm>
#include <cmath>

namespace snede {

VertexParents VertexParents::barycentric(std::span<const VertexId> vertices, std::span<const double> weights) {
  if (vertices.size() != weights.size() || vertices.empty())
    throw std::invalid_argument("barycentric parents: " + std::to_string(vertices.size()) + " vertices and " +
                                std::to_string(weights.size()) + " weights (need the same, at least one)");
  double sum = 0;
  for (double w : weights) {
    if (!std::isfinite(w)) throw std::invalid_argument("barycentric parents: weight " + std::to_string(w) + " is not finite");
    sum += w;
  }
  if (std::abs(sum - 1) > 1e-12)
    throw std::invalid_argument("barycentric parents: weights sum to " + std::to_string(sum) + ", not 1");
  return {{vertices.begin(), vertices.end()}, {weights.begin(), weights.end()}};
}

void replay_vertex_events(std::span<double> values, int components, std::span<const VertexEvent> events) {
  const auto d = static_cast<std::size_t>(components);
  std::vector<double> x(d);
  for (const VertexEvent& event : events) {
    double* at = values.data() + static_cast<std::size_t>(event.vertex) * d;
    if (event.kind == VertexEventKind::removed || event.parents.count() == 0) {
      if (event.kind != VertexEventKind::moved) std::fill(at, at + d, 0.0);  // moved to coordinates: kept
      continue;
    }
    std::fill(x.begin(), x.end(), 0.0);  // parents' values as they were before this event
    for (std::size_t i = 0; i < event.parents.count(); ++i)
      for (std::size_t k = 0; k < d; ++k)
        x[k] += event.parents.weight[i] * values[static_cast<std::size_t>(event.parents.vertex[i]) * d + k];
    std::copy(x.begin(), x.end(), at);
  }
}

}  // namespace snede
