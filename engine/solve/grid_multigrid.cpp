#include "solve/grid_multigrid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>

#include "core/csr_matrix.hpp"
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

void GridMultigrid::require_valid_width(double grid_width) {
  // Narrower than a vertex spacing, the grid has more nodes than the mesh has vertices.
  if (!(grid_width >= 1) || !std::isfinite(grid_width))
    throw std::invalid_argument("mg_grid_width must be at least 1 (vertex spacings; a finer grid has more unknowns "
                                "than the mesh), got " + std::to_string(grid_width));
}

GridMultigrid::GridMultigrid(Model& fine, double grid_width)
    : GalerkinMultigrid(fine) {
  const Mesh& mesh = fine.body().mesh();
  require_valid_width(grid_width);
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
  // The stars list every cell once: the spacing reads them rather than the mesh again.
  const VertexStars stars = all_vertex_stars(mesh.connectivity(), mesh.n_points());
  double width = grid_width * vertex_spacing(mesh, stars);
  for (int k = 0; k < d; ++k) width = std::max(width, (high[k] - low[k]) / 1e6);  // at most 10⁶ nodes a side
  const KuhnGrid grid(d, low, high, width);
  std::vector<GridWeights> weights(n);
  // The node of each (vertex, slot) pair the vertex uses, -1 for the others.
  std::vector<std::int64_t> used_node(n * slots, -1);
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v)) {
      weights[v] = grid.locate(mesh.point(v));
      for (int s = 0; s < slots; ++s)
        if (weights[v].node[s] >= 0 && weights[v].weight[s] > negligible_weight) used_node[v * slots + s] = weights[v].node[s];
    }

  // Virtual nodes: (vertex, slot) pairs on the same grid node are one copy of it when a fine
  // edge joins them, so that each copy spans one connected piece of the node's fine vertices.
  DisjointSets copies(n * slots);
  auto join = [&](VertexId i, VertexId j) {
    for (int s = 0; s < slots; ++s) {
      const std::int64_t node = used_node[i * slots + s];
      if (node < 0) continue;
      for (int t = 0; t < slots; ++t)
        if (used_node[j * slots + t] == node)
          copies.unite(static_cast<std::int32_t>(i * slots + s), static_cast<std::int32_t>(j * slots + t));
    }
  };
  // Each edge once (from its lower end), found in the vertex stars: an edge lies in about five
  // tetrahedra, and this runs after every edit.
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
  for (std::size_t i = 0; i < n * slots; ++i) {
    if (used_node[i] < 0) continue;
    const std::int32_t root = copies.find(static_cast<std::int32_t>(i));
    if (copy_of[root] < 0) {
      copy_of[root] = static_cast<std::int32_t>(count.size());
      count.push_back(0);
    }
    copy_of[i] = copy_of[root];
    ++count[copy_of[root]];
  }
  const std::size_t n_copies = count.size();
  std::vector<std::size_t> start(n_copies + 1, 0);
  for (std::size_t k = 0; k < n_copies; ++k) start[k + 1] = start[k] + count[k];
  std::vector<std::size_t> members(start.back()), fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n * slots; ++i)
    if (copy_of[i] >= 0) members[fill[copy_of[i]]++] = i;

  // Each copy's columns: weight · P_v for its vertices, orthonormalised (a copy whose vertices
  // are all fixed has none; sliding ones keep the directions they allow). They are kept by
  // member, d × d row-major with the copy's columns from the left (BlockInterpolation's blocks).
  const int dd = d * d;
  std::vector<double> member_block(members.size() * dd, 0.0);
  std::vector<PetscInt> first_column(n_copies + 1, 0);
  std::vector<double> projections(members.size() * dd), block, Q;
  for (std::size_t k = 0; k < n_copies; ++k) {
    bool all_free = true;
    for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
      const std::span<double> P(projections.data() + m * dd, dd);
      fine.constraints().projection_block(static_cast<VertexId>(members[m] / slots), P);
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) all_free = all_free && P[i * d + j] == (i == j ? 1.0 : 0.0);
    }
    // Free vertices only: column j is the weights on the j components, orthogonal to the
    // others, so Gram-Schmidt only divides it by its norm — the same operations, done here
    // without the zeros (which leave its sums unchanged).
    double sum_of_squares = 0;
    for (std::size_t m = start[k]; all_free && m < start[k + 1]; ++m) {
      const double w = weights[members[m] / slots].weight[members[m] % slots];
      sum_of_squares += w * w;
    }
    if (all_free && sum_of_squares > 0) {
      const double norm = std::sqrt(sum_of_squares);
      for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
        const double q = weights[members[m] / slots].weight[members[m] % slots] / norm;
        for (int i = 0; i < d; ++i) member_block[m * dd + i * d + i] = q;
      }
      first_column[k + 1] = first_column[k] + d;
      continue;
    }
    const std::size_t rows = (start[k + 1] - start[k]) * d;
    block.assign(rows * d, 0.0);
    for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
      const double w = weights[members[m] / slots].weight[members[m] % slots];
      const std::size_t row = (m - start[k]) * d;
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) block[static_cast<std::size_t>(j) * rows + row + i] = w * projections[m * dd + i * d + j];
    }
    const std::size_t columns = orthonormalise_columns(block, rows, d, Q);
    for (std::size_t m = start[k]; m < start[k + 1]; ++m)
      for (int i = 0; i < d; ++i)
        for (std::size_t p = 0; p < columns; ++p)
          member_block[m * dd + i * d + p] = Q[p * rows + (m - start[k]) * d + i];
    first_column[k + 1] = first_column[k] + static_cast<PetscInt>(columns);
  }
  n_nodes_ = n_copies;
  n_unknowns_ = first_column.back();
  // The same interpolation by vertex blocks, each vertex's in copy order, for the Galerkin
  // product; copies without columns (all their vertices fixed) give no block.
  blocks_.dim = d;
  blocks_.first_column = first_column;
  blocks_.start.assign(n + 1, 0);
  for (std::size_t k = 0; k < n_copies; ++k)
    if (first_column[k + 1] > first_column[k])
      for (std::size_t m = start[k]; m < start[k + 1]; ++m) ++blocks_.start[members[m] / slots + 1];
  std::partial_sum(blocks_.start.begin(), blocks_.start.end(), blocks_.start.begin());
  blocks_.copy.resize(blocks_.start.back());
  blocks_.block.resize(blocks_.start.back() * dd);
  std::vector<std::size_t> next_entry(blocks_.start.begin(), blocks_.start.end() - 1);
  for (std::size_t k = 0; k < n_copies; ++k) {
    if (first_column[k + 1] == first_column[k]) continue;
    for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
      const std::size_t entry = next_entry[members[m] / slots]++;
      blocks_.copy[entry] = static_cast<PetscInt>(k);
      std::copy_n(member_block.begin() + static_cast<std::ptrdiff_t>(m * dd), dd,
                  blocks_.block.begin() + static_cast<std::ptrdiff_t>(entry * dd));
    }
  }

  // P in CSR from the blocks, vertex by vertex: a vertex's copies ascend, so each row comes out
  // sorted. Without the exact zeros of the copies' columns (a free vertex has one non-zero of
  // its copy's three columns): they would cost every restriction and interpolation.
  const auto n_rows = static_cast<PetscInt>(n * d);
  auto csr = std::make_unique<CsrArrays>();
  csr->row_start.reserve(static_cast<std::size_t>(n_rows) + 1);
  csr->row_start.push_back(0);
  csr->columns.reserve(blocks_.block.size() / d);
  csr->values.reserve(blocks_.block.size() / d);
  for (std::size_t v = 0; v < n; ++v)
    for (int i = 0; i < d; ++i) {
      for (std::size_t entry = blocks_.start[v]; entry < blocks_.start[v + 1]; ++entry) {
        const PetscInt k = blocks_.copy[entry];
        for (PetscInt p = 0; p < blocks_.columns(k); ++p) {
          const double value = blocks_.block[entry * dd + i * d + p];
          if (value == 0) continue;
          csr->columns.push_back(first_column[k] + p);
          csr->values.push_back(value);
        }
      }
      csr->row_start.push_back(static_cast<PetscInt>(csr->columns.size()));
    }
  interpolation_ = matrix_owning(std::move(csr), n_rows, n_unknowns_);
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
