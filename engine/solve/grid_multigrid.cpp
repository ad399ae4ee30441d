#include "solve/grid_multigrid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "mesh/traversal.hpp"
#include "solve/coarse_basis.hpp"

namespace snede {
namespace {

// A weight below this is a vertex on the far face of its grid simplex: it does not use the node.
constexpr double negligible_weight = 1e-12;

// A fine vertex's grid simplex: the grid nodes (linear indices) and barycentric weights.
struct GridWeights {
  std::array<std::int64_t, 4> node{-1, -1, -1, -1};
  std::array<double, 4> weight{};
};

// The grid of cubes (squares) of side `width` from `low`, each split into Kuhn simplices: the
// simplex holding a point is given by the order of its local coordinates t, its corners walk
// from the cell's lower corner along the axes in decreasing t, and its weights are the gaps
// between consecutive sorted coordinates. Neighbouring cells agree on shared faces, so the
// interpolation is continuous.
class KuhnGrid {
 public:
  KuhnGrid(int dim, std::array<double, 3> low, std::array<double, 3> high, double width) : dim_(dim), low_(low), width_(width) {
    for (int k = 0; k < dim; ++k) nodes_[k] = static_cast<std::int64_t>(std::floor((high[k] - low[k]) / width)) + 2;
  }
  GridWeights locate(std::span<const double> x) const {
    std::array<std::int64_t, 3> cell{};
    std::array<double, 3> t{};
    std::array<int, 3> axis{0, 1, 2};
    for (int k = 0; k < dim_; ++k) {
      const double local = (x[k] - low_[k]) / width_;
      cell[k] = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(local)), 0, nodes_[k] - 2);
      t[k] = std::clamp(local - static_cast<double>(cell[k]), 0.0, 1.0);
    }
    std::sort(axis.begin(), axis.begin() + dim_, [&](int a, int b) { return t[a] > t[b]; });
    GridWeights result;
    std::array<std::int64_t, 3> corner = cell;
    double previous = 1.0;
    for (int i = 0; i <= dim_; ++i) {
      const double next = i < dim_ ? t[axis[i]] : 0.0;
      result.node[i] = index(corner);
      result.weight[i] = previous - next;
      previous = next;
      if (i < dim_) ++corner[axis[i]];
    }
    return result;
  }

 private:
  std::int64_t index(const std::array<std::int64_t, 3>& corner) const {
    return corner[0] + nodes_[0] * (corner[1] + nodes_[1] * corner[2]);
  }
  int dim_;
  std::array<double, 3> low_;
  double width_;
  std::array<std::int64_t, 3> nodes_{1, 1, 1};
};

}  // namespace

GridMultigrid::GridMultigrid(Model& fine, double grid_width)
    : GalerkinMultigrid(fine) {
  const Mesh& mesh = fine.body().mesh();
  if (!(grid_width > 0) || !std::isfinite(grid_width))
    throw std::invalid_argument("mg_grid_width must be positive (mean edge lengths), got " + std::to_string(grid_width));
  // A fine vertex uses the d + 1 nodes of its grid simplex (its slots); a cell has cell_dim + 1
  // corners (3 on a membrane in 3D).
  const int d = mesh.dim(), slots = d + 1, corners = mesh.cell_dim() + 1;
  const auto n = static_cast<std::size_t>(mesh.n_points());
  std::array<double, 3> low{}, high{};
  low.fill(std::numeric_limits<double>::infinity());
  high.fill(-std::numeric_limits<double>::infinity());
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v))
      for (int k = 0; k < d; ++k) {
        low[k] = std::min(low[k], mesh.point(v)[k]);
        high[k] = std::max(high[k], mesh.point(v)[k]);
      }
  double width = grid_width * mean_edge_length(mesh);
  for (int k = 0; k < d; ++k) width = std::max(width, (high[k] - low[k]) / 1e6);  // at most 10⁶ nodes a side
  const KuhnGrid grid(d, low, high, width);
  std::vector<GridWeights> weights(n);
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v)) weights[v] = grid.locate(mesh.point(v));

  // Virtual nodes: (vertex, slot) pairs on the same grid node are one copy of it when a fine
  // edge joins them, so that each copy spans one connected piece of the node's fine vertices.
  DisjointSets copies(n * slots);
  auto uses = [&](VertexId v, int s) { return weights[v].node[s] >= 0 && weights[v].weight[s] > negligible_weight; };
  auto join = [&](VertexId i, VertexId j) {
    for (int s = 0; s < slots; ++s) {
      if (!uses(i, s)) continue;
      for (int t = 0; t < slots; ++t)
        if (uses(j, t) && weights[i].node[s] == weights[j].node[t])
          copies.unite(static_cast<std::int32_t>(i * slots + s), static_cast<std::int32_t>(j * slots + t));
    }
  };
  // Each edge once (from its lower end), found in the vertex stars: an edge lies in about five
  // tetrahedra, and this runs after every edit.
  const VertexStars stars = all_vertex_stars(mesh.connectivity(), mesh.n_points());
  std::vector<VertexId> last_seen_from(n, no_id);
  for (VertexId i = 0; i < mesh.n_points(); ++i)
    for (std::size_t e = stars.start[i]; e < stars.start[i + 1]; ++e)
      for (VertexId j : std::span(stars.vertices[stars.element_of(stars.entries[e])]).first(corners))
        if (j > i && last_seen_from[j] != i) {
          last_seen_from[j] = i;
          join(i, j);
        }
  // Members of each copy, in vertex order.
  std::vector<std::int32_t> copy_of(n * slots, -1);
  std::vector<std::size_t> count;
  for (std::size_t v = 0; v < n; ++v)
    for (int s = 0; s < slots; ++s) {
      if (!mesh.is_vertex(static_cast<VertexId>(v)) || !uses(static_cast<VertexId>(v), s)) continue;
      const std::int32_t root = copies.find(static_cast<std::int32_t>(v * slots + s));
      if (copy_of[root] < 0) {
        copy_of[root] = static_cast<std::int32_t>(count.size());
        count.push_back(0);
      }
      copy_of[v * slots + s] = copy_of[root];
      ++count[copy_of[root]];
    }
  const std::size_t n_copies = count.size();
  std::vector<std::size_t> start(n_copies + 1, 0);
  for (std::size_t k = 0; k < n_copies; ++k) start[k + 1] = start[k] + count[k];
  std::vector<std::size_t> members(start.back()), fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n * slots; ++i)
    if (copy_of[i] >= 0) members[fill[copy_of[i]]++] = i;

  // Each copy's columns: weight · P_v for its vertices, orthonormalised (a copy whose vertices
  // are all fixed has none; sliding ones keep the directions they allow).
  std::vector<std::vector<double>> Q(n_copies);
  std::vector<PetscInt> first_column(n_copies + 1, 0);
  std::vector<double> block, R, P(static_cast<std::size_t>(d) * d);
  for (std::size_t k = 0; k < n_copies; ++k) {
    const std::size_t rows = (start[k + 1] - start[k]) * d;
    block.assign(rows * d, 0.0);
    for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
      const auto v = static_cast<VertexId>(members[m] / slots);
      const double w = weights[v].weight[members[m] % slots];
      fine.constraints().projection_block(v, P);
      const std::size_t row = (m - start[k]) * d;
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) block[static_cast<std::size_t>(j) * rows + row + i] = w * P[i * d + j];
    }
    Q[k] = orthonormal_columns(block, rows, d, R);
    first_column[k + 1] = first_column[k] + static_cast<PetscInt>(rows ? Q[k].size() / rows : 0);
  }
  n_nodes_ = n_copies;
  n_unknowns_ = first_column.back();
  // The same interpolation by vertex blocks (d × d, a copy's columns from the left), for the
  // Galerkin product; copies without columns (all their vertices fixed) give no block.
  const int dd = d * d;
  blocks_.dim = d;
  blocks_.first_column = first_column;
  blocks_.start.assign(n + 1, 0);
  for (std::size_t k = 0; k < n_copies; ++k)
    if (first_column[k + 1] > first_column[k])
      for (std::size_t m = start[k]; m < start[k + 1]; ++m) ++blocks_.start[members[m] / slots + 1];
  std::partial_sum(blocks_.start.begin(), blocks_.start.end(), blocks_.start.begin());
  blocks_.copy.resize(blocks_.start.back());
  blocks_.block.assign(blocks_.start.back() * dd, 0.0);
  std::vector<std::size_t> next_entry(blocks_.start.begin(), blocks_.start.end() - 1);
  for (std::size_t k = 0; k < n_copies; ++k) {
    const std::size_t rows = (start[k + 1] - start[k]) * d;
    const PetscInt columns = first_column[k + 1] - first_column[k];
    if (columns == 0) continue;
    for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
      const std::size_t entry = next_entry[members[m] / slots]++;
      blocks_.copy[entry] = static_cast<PetscInt>(k);
      for (int i = 0; i < d; ++i)
        for (PetscInt p = 0; p < columns; ++p)
          blocks_.block[entry * dd + i * d + p] = Q[k][static_cast<std::size_t>(p) * rows + (m - start[k]) * d + i];
    }
  }

  // P in CSR, filled copy by copy: the columns grow with the copy, so each row comes out sorted.
  const auto n_rows = static_cast<PetscInt>(n * d);
  std::vector<PetscInt> row_start(static_cast<std::size_t>(n_rows) + 1, 0);
  for (std::size_t i = 0; i < n * slots; ++i)
    if (copy_of[i] >= 0)
      for (int r = 0; r < d; ++r)
        row_start[(i / slots) * d + r + 1] += first_column[copy_of[i] + 1] - first_column[copy_of[i]];
  std::partial_sum(row_start.begin(), row_start.end(), row_start.begin());
  std::vector<PetscInt> columns(static_cast<std::size_t>(row_start.back()));
  std::vector<double> values(columns.size());
  std::vector<PetscInt> next(row_start.begin(), row_start.end() - 1);
  for (std::size_t k = 0; k < n_copies; ++k) {
    const std::size_t rows = (start[k + 1] - start[k]) * d;
    for (std::size_t m = start[k]; m < start[k + 1]; ++m)
      for (int i = 0; i < d; ++i) {
        const std::size_t row = (m - start[k]) * d + i;
        PetscInt& at = next[(members[m] / slots) * d + i];
        for (PetscInt p = 0; p < first_column[k + 1] - first_column[k]; ++p, ++at) {
          columns[at] = first_column[k] + p;
          values[at] = Q[k][static_cast<std::size_t>(p) * rows + row];
        }
      }
  }
  // Without the exact zeros of the copies' columns (a free vertex has one non-zero of its
  // copy's three columns): they would cost every restriction and interpolation.
  PetscInt kept = 0;
  for (PetscInt row = 0, k = 0; row < n_rows; ++row) {
    for (; k < row_start[row + 1]; ++k)
      if (values[k] != 0) {
        columns[kept] = columns[k];
        values[kept++] = values[k];
      }
    row_start[row + 1] = kept;
  }
  SNEDE_PETSC(MatCreate(PETSC_COMM_SELF, interpolation_.out()));
  SNEDE_PETSC(MatSetSizes(interpolation_, n_rows, n_unknowns_, n_rows, n_unknowns_));
  SNEDE_PETSC(MatSetType(interpolation_, MATSEQAIJ));
  SNEDE_PETSC(MatSeqAIJSetPreallocationCSR(interpolation_, row_start.data(), columns.data(), values.data()));
}

std::vector<std::size_t> GridMultigrid::level_sizes() const { return {n_nodes_, fine_.body().mesh().n_cells()}; }

std::vector<std::size_t> GridMultigrid::level_unknowns() const {
  return {static_cast<std::size_t>(n_unknowns_), static_cast<std::size_t>(fine_.n_dofs())};
}

std::unique_ptr<CoarseProduct> GridMultigrid::galerkin_product(Mat finer, PetscInt) const {
  return block_galerkin_product(finer, blocks_);
}

void GridMultigrid::configure(PC pc, const SolverOptions& options, const std::vector<double>&) {
  configure_levels(pc, {interpolation_.get()}, options);
}

}  // namespace snede
