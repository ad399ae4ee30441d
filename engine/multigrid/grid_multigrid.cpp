#include "multigrid/grid_multigrid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include "core/csr_matrix.hpp"
#include "core/error.hpp"
#include "mesh/traversal.hpp"
#include "multigrid/coarse_basis.hpp"

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
  explicit KuhnGrid(const GridGeometry& g) : dim_(g.dim), low_(g.low), width_(g.width) {
    for (int k = 0; k < dim_; ++k) nodes_[k] = static_cast<std::int64_t>(std::floor((g.high[k] - g.low[k]) / width_)) + 2;
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

GridGeometry GridMultigrid::geometry_for(const Mesh& mesh, double grid_width) {
  require_valid_width(grid_width);
  GridGeometry g;
  g.dim = mesh.dim();
  g.low.fill(std::numeric_limits<double>::infinity());
  g.high.fill(-std::numeric_limits<double>::infinity());
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v))
      for (int k = 0; k < g.dim; ++k) {
        g.low[k] = std::min(g.low[k], mesh.point(v)[k]);
        g.high[k] = std::max(g.high[k], mesh.point(v)[k]);
      }
  const VertexStars stars = all_vertex_stars(mesh.connectivity(), mesh.n_points());
  g.width = grid_width * vertex_spacing(mesh, stars);
  for (int k = 0; k < g.dim; ++k) g.width = std::max(g.width, (g.high[k] - g.low[k]) / 1e6);  // at most 10⁶ nodes a side
  return g;
}

GridMultigrid::GridMultigrid(Model& fine, double grid_width)
    : GridMultigrid(fine, geometry_for(fine.body().mesh(), grid_width)) {}

GridMultigrid::GridMultigrid(Model& fine, const GridGeometry& geometry)
    : GalerkinMultigrid(fine),
      geometry_(geometry),
      edits_(std::make_unique<EditFootprint>(fine.body().mesh().connectivity())) {
  const Mesh& mesh = fine.body().mesh();
  const std::size_t slots = static_cast<std::size_t>(geometry_.dim) + 1;
  const auto n = static_cast<std::size_t>(mesh.n_points());
  pair_node_.assign(n * slots, -1);
  pair_weight_.assign(n * slots, 0.0);
  for (VertexId v = 0; v < mesh.n_points(); ++v) locate(v);
  DisjointSets copies(n * slots);
  join_linked_pairs(copies, nullptr);
  std::vector<std::int32_t> label(n * slots, -1);
  for (std::size_t i = 0; i < n * slots; ++i)
    if (pair_node_[i] >= 0) label[i] = copies.find(static_cast<std::int32_t>(i));
  make_levels(label);
}

std::unique_ptr<Multigrid> GridMultigrid::follow_edits() {
  const std::size_t slots = static_cast<std::size_t>(geometry_.dim) + 1;
  if (static_cast<std::size_t>(fine_.body().mesh().n_points()) * slots < pair_node_.size()) return nullptr;
  return std::unique_ptr<Multigrid>(new GridMultigrid(fine_, *this));
}

GridMultigrid::GridMultigrid(Model& fine, const GridMultigrid& earlier)
    : GalerkinMultigrid(fine),
      geometry_(earlier.geometry_),
      edits_(std::make_unique<EditFootprint>(fine.body().mesh().connectivity())) {
  const std::size_t slots = static_cast<std::size_t>(geometry_.dim) + 1;
  const auto n = static_cast<std::size_t>(fine.body().mesh().n_points());
  const std::size_t n_earlier = earlier.pair_node_.size() / slots;
  // The vertices the edits touched or added are located again; a grid node one of them uses or
  // used is dirty: its copies are found again. Every other node's users and their edges are
  // those of the earlier mesh, and so are its copies.
  std::vector<bool> touched(n, false);
  for (VertexId v : earlier.edits_->vertices())
    if (static_cast<std::size_t>(v) < n) touched[v] = true;
  for (std::size_t v = n_earlier; v < n; ++v) touched[v] = true;
  pair_node_ = earlier.pair_node_;
  pair_weight_ = earlier.pair_weight_;
  pair_node_.resize(n * slots, -1);
  pair_weight_.resize(n * slots, 0.0);
  std::unordered_set<std::int64_t> dirty_nodes;
  for (std::size_t v = 0; v < n; ++v) {
    if (!touched[v]) continue;
    for (std::size_t s = 0; s < slots && v < n_earlier; ++s)
      if (earlier.pair_node_[v * slots + s] >= 0) dirty_nodes.insert(earlier.pair_node_[v * slots + s]);
    locate(static_cast<VertexId>(v));
    for (std::size_t s = 0; s < slots; ++s)
      if (pair_node_[v * slots + s] >= 0) dirty_nodes.insert(pair_node_[v * slots + s]);
  }
  std::vector<bool> dirty_copy(earlier.copy_node_.size());
  for (std::size_t k = 0; k < dirty_copy.size(); ++k) dirty_copy[k] = dirty_nodes.count(earlier.copy_node_[k]) > 0;
  // A pair on a dirty node: a touched vertex's, or an untouched one's whose copy was dirty.
  std::vector<bool> on_dirty_node(n, false);
  std::vector<std::int32_t> label(n * slots, -1);
  const auto kept_labels = static_cast<std::int32_t>(earlier.copy_node_.size());
  for (std::size_t i = 0; i < n * slots; ++i) {
    if (pair_node_[i] < 0) continue;
    const std::size_t v = i / slots;
    if (touched[v] || dirty_copy[earlier.pair_copy_[i]]) {
      on_dirty_node[v] = true;
    } else {
      label[i] = earlier.pair_copy_[i];
    }
  }
  DisjointSets copies(n * slots);
  join_linked_pairs(copies, &on_dirty_node);
  for (std::size_t i = 0; i < n * slots; ++i)
    if (pair_node_[i] >= 0 && label[i] < 0) label[i] = kept_labels + copies.find(static_cast<std::int32_t>(i));
  make_levels(label);
}

void GridMultigrid::locate(VertexId v) {
  const Mesh& mesh = fine_.body().mesh();
  const std::size_t slots = static_cast<std::size_t>(geometry_.dim) + 1;
  std::fill_n(pair_node_.begin() + static_cast<std::ptrdiff_t>(v * slots), slots, -1);
  std::fill_n(pair_weight_.begin() + static_cast<std::ptrdiff_t>(v * slots), slots, 0.0);
  if (!mesh.is_vertex(v)) return;
  const GridWeights weights = KuhnGrid(geometry_).locate(mesh.point(v));
  for (std::size_t s = 0; s < slots; ++s)
    if (weights.node[s] >= 0 && weights.weight[s] > negligible_weight) {
      pair_node_[v * slots + s] = weights.node[s];
      pair_weight_[v * slots + s] = weights.weight[s];
    }
}

void GridMultigrid::join_linked_pairs(DisjointSets& copies, const std::vector<bool>* marked) const {
  // Virtual nodes: (vertex, slot) pairs on the same grid node are one copy of it when a fine
  // edge joins them, so that each copy spans one connected piece of the node's fine vertices.
  // An element's corners are joined pairwise by its edges: its pairs on one node are joined
  // (sorted by node, each to the next on the same node).
  const Connectivity& c = fine_.body().mesh().connectivity();
  const std::size_t slots = static_cast<std::size_t>(geometry_.dim) + 1;
  std::array<std::pair<std::int64_t, std::int32_t>, (max_dimension + 1) * (max_dimension + 1)> on_node{};
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    const std::span<const VertexId> corners = c.element(e).simplex.vertices();
    if (marked && std::none_of(corners.begin(), corners.end(), [&](VertexId v) { return (*marked)[v]; })) continue;
    std::size_t count = 0;
    for (VertexId v : corners)
      for (std::size_t s = 0; s < slots; ++s)
        if (pair_node_[v * slots + s] >= 0)
          on_node[count++] = {pair_node_[v * slots + s], static_cast<std::int32_t>(v * slots + s)};
    std::sort(on_node.begin(), on_node.begin() + static_cast<std::ptrdiff_t>(count));
    for (std::size_t k = 1; k < count; ++k)
      if (on_node[k].first == on_node[k - 1].first) copies.unite(on_node[k].second, on_node[k - 1].second);
  }
}

void GridMultigrid::make_levels(const std::vector<std::int32_t>& label) {
  const int d = geometry_.dim;
  const std::size_t slots = static_cast<std::size_t>(d) + 1;
  const std::size_t n = pair_node_.size() / slots;
  // Each label's copy number, in the order of the copies' first pairs, and their members.
  std::vector<std::int32_t> copy_of_label(*std::max_element(label.begin(), label.end()) + 1, -1);
  pair_copy_.assign(n * slots, -1);
  copy_node_.clear();
  std::vector<std::size_t> count;
  for (std::size_t i = 0; i < n * slots; ++i) {
    if (label[i] < 0) continue;
    std::int32_t& copy = copy_of_label[label[i]];
    if (copy < 0) {
      copy = static_cast<std::int32_t>(count.size());
      count.push_back(0);
      copy_node_.push_back(pair_node_[i]);
    }
    pair_copy_[i] = copy;
    ++count[copy];
  }
  const std::vector<std::int32_t>& copy_of = pair_copy_;
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
  const Constraints& constraints = fine_.constraints();
  if (constraints.n_points() < static_cast<VertexId>(n)) throw std::logic_error("grid levels: constraints for fewer vertices than the mesh's");
  for (std::size_t k = 0; k < n_copies; ++k) {
    bool all_free = true;  // P = I at every member
    for (std::size_t m = start[k]; m < start[k + 1] && all_free; ++m)
      all_free = constraints[static_cast<VertexId>(members[m] / slots)].kind == ConstraintKind::free;
    // Free vertices only: column j is the weights on the j components, orthogonal to the
    // others, so Gram-Schmidt only divides it by its norm — the same operations, done here
    // without the zeros (which leave its sums unchanged).
    double sum_of_squares = 0;
    for (std::size_t m = start[k]; all_free && m < start[k + 1]; ++m) {
      const double w = pair_weight_[members[m]];
      sum_of_squares += w * w;
    }
    if (all_free && sum_of_squares > 0) {
      const double norm = std::sqrt(sum_of_squares);
      for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
        const double q = pair_weight_[members[m]] / norm;
        for (int i = 0; i < d; ++i) member_block[m * dd + i * d + i] = q;
      }
      first_column[k + 1] = first_column[k] + d;
      continue;
    }
    const std::size_t rows = (start[k + 1] - start[k]) * d;
    block.assign(rows * d, 0.0);
    for (std::size_t m = start[k]; m < start[k + 1]; ++m)
      constraints.projection_block(static_cast<VertexId>(members[m] / slots), std::span<double>(projections.data() + m * dd, dd));
    for (std::size_t m = start[k]; m < start[k + 1]; ++m) {
      const double w = pair_weight_[members[m]];
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
