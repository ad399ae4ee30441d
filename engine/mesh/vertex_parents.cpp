#include "mesh/vertex_parents.hpp"

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

}  // namespace snede
