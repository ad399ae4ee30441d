#include "problem/projected_stiffness.hpp"

#include <cmath>
#include <variant>

namespace snede {

double constraint_stiffness(const Material& material, int cell_dim, double thickness, double volume, double cells) {
  const Lame lame = std::visit([](const auto& m) { return m.lame; }, material);
  double c = 0;
  if (cell_dim == 3) {
    c = (lame.lambda + 2 * lame.mu) * std::cbrt(volume / cells);
  } else {
    // E/(1 − ν²) = 4μ(λ + μ)/(λ + 2μ), in an order that neither overflows nor underflows.
    c = 4 * lame.mu * ((lame.lambda + lame.mu) / (lame.lambda + 2 * lame.mu)) * thickness;
  }
  return std::isfinite(c) && c > 0 ? c : 1.0;
}

double volume_of_cells(const Mesh& mesh) {
  if (mesh.cell_dim() != 3) return 0.0;
  double volume = 0;
  for (ElementId e : mesh.connectivity().element_ids()) volume += std::abs(mesh.measure(e));
  return volume;
}

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
