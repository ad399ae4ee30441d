#include "solve/coarse_basis.hpp"

#include <cmath>

namespace snede {
namespace {

constexpr double rank_tolerance = 1e-8;

}  // namespace

std::vector<double> orthonormal_columns(const std::vector<double>& block, std::size_t rows, int m,
                                        std::vector<double>& R) {
  std::vector<double> Q;
  for (int j = 0; j < m; ++j) {
    std::vector<double> w(block.begin() + static_cast<std::ptrdiff_t>(j * rows),
                          block.begin() + static_cast<std::ptrdiff_t>((j + 1) * rows));
    double original = 0;
    for (double x : w) original += x * x;
    if (original == 0) continue;
    const std::size_t k = Q.size() / rows;
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t p = 0; p < k; ++p) {
        double dot = 0;
        for (std::size_t r = 0; r < rows; ++r) dot += Q[p * rows + r] * w[r];
        for (std::size_t r = 0; r < rows; ++r) w[r] -= dot * Q[p * rows + r];
      }
    double norm = 0;
    for (double x : w) norm += x * x;
    if (norm <= rank_tolerance * rank_tolerance * original) continue;
    norm = std::sqrt(norm);
    for (double& x : w) Q.push_back(x / norm);
  }
  const std::size_t k = Q.size() / rows;
  R.assign(k * m, 0.0);
  for (std::size_t p = 0; p < k; ++p)
    for (int j = 0; j < m; ++j) {
      double dot = 0;
      for (std::size_t r = 0; r < rows; ++r) dot += Q[p * rows + r] * block[static_cast<std::size_t>(j) * rows + r];
      R[p * m + j] = dot;
    }
  return Q;
}

double mean_edge_length(const Mesh& mesh) {
  const std::vector<VertexId> cells = mesh.cells();
  const int nv = mesh.cell_dim() + 1, d = mesh.dim();
  double length = 0;
  std::size_t count = 0;
  for (std::size_t c = 0; c < cells.size(); c += nv)
    for (int a = 0; a < nv; ++a)
      for (int b = a + 1; b < nv; ++b) {
        const std::span<const double> x = mesh.point(cells[c + a]), y = mesh.point(cells[c + b]);
        double squared = 0;
        for (int k = 0; k < d; ++k) squared += (x[k] - y[k]) * (x[k] - y[k]);
        length += std::sqrt(squared);
        ++count;
      }
  return count ? length / static_cast<double>(count) : 0.0;
}

}  // namespace snede
