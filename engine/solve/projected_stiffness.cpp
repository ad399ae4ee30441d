#include "solve/projected_stiffness.hpp"

namespace snede {

std::vector<double> projection_blocks(const Constraints& constraints, VertexId n_points) {
  const int d = constraints.dim();
  std::vector<double> blocks(static_cast<std::size_t>(n_points) * d * d);
  for (VertexId v = 0; v < n_points; ++v)
    constraints.projection_block(v, std::span<double>(blocks).subspan(static_cast<std::size_t>(v) * d * d, d * d));
  return blocks;
}

std::vector<double> complement_blocks(const std::vector<double>& P, int d) {
  std::vector<double> blocks(P.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) blocks[i] = ((i % (d * d)) % (d + 1) == 0 ? 1.0 : 0.0) - P[i];
  return blocks;
}

}  // namespace snede
