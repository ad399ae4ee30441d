#include "multigrid/coarse_basis.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "mesh/element_quality.hpp"

namespace snede {
namespace {

constexpr double rank_tolerance = 1e-8;

// Σ over cells and their vertex pairs of the edge lengths, in cell order, and the number of
// edges; `cell(k)` gives cell k's vertices.
template <class CellVertices>
double mean_edge_length_of(const Mesh& mesh, std::size_t n_cells, CellVertices&& cell) {
  const int nv = mesh.cell_dim() + 1, d = mesh.dim();
  const std::vector<double>& points = mesh.points();
  double length = 0;
  for (std::size_t c = 0; c < n_cells; ++c) {
    const auto& vertices = cell(c);
    for (int a = 0; a < nv; ++a)
      for (int b = a + 1; b < nv; ++b) {
        const double* x = points.data() + static_cast<std::size_t>(vertices[a]) * d;
        const double* y = points.data() + static_cast<std::size_t>(vertices[b]) * d;
        double squared = 0;
        for (int k = 0; k < d; ++k) squared += (x[k] - y[k]) * (x[k] - y[k]);
        length += std::sqrt(squared);
      }
  }
  const std::size_t count = n_cells * static_cast<std::size_t>(nv * (nv - 1) / 2);
  return count ? length / static_cast<double>(count) : 0.0;
}

}  // namespace

std::size_t orthonormalise_columns(std::span<const double> block, std::size_t rows, int m, std::vector<double>& Q) {
  Q.clear();
  std::size_t k = 0;
  for (int j = 0; j < m; ++j) {
    const auto column = block.subspan(static_cast<std::size_t>(j) * rows, rows);
    double original = 0;
    for (double x : column) original += x * x;
    if (original == 0) continue;
    // The candidate is written after the kept columns and dropped again if it depends on them.
    Q.resize((k + 1) * rows);
    double* w = Q.data() + k * rows;
    std::copy(column.begin(), column.end(), w);
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t p = 0; p < k; ++p) {
        const double* q = Q.data() + p * rows;
        double dot = 0;
        for (std::size_t r = 0; r < rows; ++r) dot += q[r] * w[r];
        for (std::size_t r = 0; r < rows; ++r) w[r] -= dot * q[r];
      }
    double norm = 0;
    for (std::size_t r = 0; r < rows; ++r) norm += w[r] * w[r];
    if (norm <= rank_tolerance * rank_tolerance * original) {
      Q.resize(k * rows);
      continue;
    }
    norm = std::sqrt(norm);
    for (std::size_t r = 0; r < rows; ++r) w[r] /= norm;
    ++k;
  }
  return k;
}

std::vector<double> orthonormal_columns(const std::vector<double>& block, std::size_t rows, int m,
                                        std::vector<double>& R) {
  std::vector<double> Q;
  const std::size_t k = orthonormalise_columns(block, rows, m, Q);
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
  const std::vector<ElementId> cells = mesh.cell_ids();
  const Connectivity& connectivity = mesh.connectivity();
  return mean_edge_length_of(mesh, cells.size(),
                             [&](std::size_t c) { return connectivity.element(cells[c]).simplex.oriented_vertices(); });
}

double vertex_spacing(const Mesh& mesh, const VertexStars& stars) {
  const int cell_dim = mesh.cell_dim(), d = mesh.dim(), corners = cell_dim + 1;
  double measure = 0;
  std::array<double, (max_dimension + 1) * 3> coordinates{};
  for (const auto& vertices : stars.vertices) {
    for (int a = 0; a < corners; ++a)
      for (int k = 0; k < d; ++k) coordinates[a * d + k] = mesh.point(vertices[a])[k];
    measure += std::abs(cell_measure(cell_dim, d, std::span<const double>(coordinates.data(), static_cast<std::size_t>(corners * d))));
  }
  std::size_t n_vertices = 0;
  for (std::size_t v = 0; v + 1 < stars.start.size(); ++v) n_vertices += stars.start[v + 1] > stars.start[v];
  return n_vertices ? std::pow(measure / static_cast<double>(n_vertices), 1.0 / cell_dim) : 0.0;
}

}  // namespace snede
