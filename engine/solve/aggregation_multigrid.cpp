#include "solve/aggregation_multigrid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "solve/coarse_basis.hpp"

namespace snede {
namespace {

// Each coarser level's cells are this much wider.
constexpr double span_growth = 2.0;
// Coarsening stops once a level has at most this many unknowns: its LU is then cheap...
constexpr PetscInt direct_unknowns = 1500;
// ...or when aggregating would keep more than this fraction of the nodes (a level that hardly
// coarsens costs a smoother without reducing the problem).
constexpr double least_reduction = 0.6;
// Grid cells are numbered in 21 bits per direction.
constexpr double max_cells_per_direction = 1 << 20;

// The nodes of one level — the mesh's vertices, or the aggregates of the finer level — with
// their share of the body's rigid motions: node i has the level's unknowns first[i] ..
// first[i + 1] and the block modes[mode_start[i] ..] of unknowns × n_modes (row-major) giving
// each rigid motion, expressed about the node's own position, in those unknowns.
struct NodeLevel {
  int dim = 0;
  int n_modes = 0;
  std::vector<double> position;  // n × dim
  std::vector<PetscInt> first;   // n + 1
  std::vector<std::size_t> mode_start;  // n + 1
  std::vector<double> modes;
  std::vector<char> active;  // a removed vertex, or an aggregate held still by its constraints, is not
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;  // nodes joined by the mesh (may repeat)

  std::size_t size() const { return active.size(); }
  int n_unknowns(std::size_t i) const { return static_cast<int>(first[i + 1] - first[i]); }
  std::span<const double> point(std::size_t i) const {
    return std::span<const double>(position).subspan(i * static_cast<std::size_t>(dim), static_cast<std::size_t>(dim));
  }
};

// The mesh's vertices as the finest level: the constraints' projection P_v gives the
// translations a vertex can make; about its own position a rotation does not move it.
NodeLevel vertex_level(const Model& model) {
  const Mesh& mesh = model.body().mesh();
  const int d = mesh.dim();
  NodeLevel level;
  level.dim = d;
  level.n_modes = d == 3 ? 6 : 3;
  const auto n = static_cast<std::size_t>(mesh.n_points());
  level.position = mesh.points();
  level.first.resize(n + 1);
  level.mode_start.resize(n + 1);
  level.active.resize(n);
  level.modes.assign(n * d * level.n_modes, 0.0);
  std::vector<double> P(static_cast<std::size_t>(d) * d);
  for (std::size_t v = 0; v <= n; ++v) {
    level.first[v] = static_cast<PetscInt>(v * d);
    level.mode_start[v] = v * d * level.n_modes;
  }
  for (std::size_t v = 0; v < n; ++v) {
    level.active[v] = mesh.is_vertex(static_cast<VertexId>(v));
    if (!level.active[v]) continue;
    model.constraints().projection_block(static_cast<VertexId>(v), P);
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j) level.modes[level.mode_start[v] + static_cast<std::size_t>(i) * level.n_modes + j] = P[i * d + j];
  }
  const std::vector<VertexId> cells = mesh.cells();
  const int nv = mesh.cell_dim() + 1;
  level.edges.reserve(cells.size() / nv * nv * (nv - 1) / 2);
  for (std::size_t c = 0; c < cells.size(); c += nv)
    for (int a = 0; a < nv; ++a)
      for (int b = a + 1; b < nv; ++b) {
        const VertexId i = cells[c + a], j = cells[c + b];
        level.edges.emplace_back(std::min(i, j), std::max(i, j));
      }
  return level;
}

// Per node its aggregate (-1 for an inactive node): the nodes in one cell of a grid of width
// `span` that the level's edges join inside that cell; a piece of fewer than dim + 1 nodes
// joins a piece it shares an edge with (it would barely coarsen). Pieces never join across a
// missing edge, so what a cut separated stays separate.
std::vector<std::int32_t> aggregate(const NodeLevel& level, double span, std::size_t& n_aggregates) {
  const int d = level.dim;
  const std::size_t n = level.size();
  std::array<double, 3> low{}, high{};
  low.fill(std::numeric_limits<double>::infinity());
  high.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i)
    if (level.active[i])
      for (int k = 0; k < d; ++k) {
        low[k] = std::min(low[k], level.point(i)[k]);
        high[k] = std::max(high[k], level.point(i)[k]);
      }
  for (int k = 0; k < d; ++k) span = std::max(span, (high[k] - low[k]) / max_cells_per_direction);
  std::vector<std::uint64_t> cell(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!level.active[i]) continue;
    std::uint64_t key = 0;
    for (int k = 0; k < d; ++k)
      key |= static_cast<std::uint64_t>(std::floor((level.point(i)[k] - low[k]) / span)) << (21 * k);
    cell[i] = key;
  }
  DisjointSets pieces(n);
  for (const auto& [i, j] : level.edges)
    if (level.active[i] && level.active[j] && cell[i] == cell[j]) pieces.unite(i, j);
  std::vector<std::int32_t> size(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (level.active[i]) ++size[pieces.find(static_cast<std::int32_t>(i))];
  for (const auto& [i, j] : level.edges) {
    if (!level.active[i] || !level.active[j]) continue;
    const std::int32_t a = pieces.find(i), b = pieces.find(j);
    if (a == b || (size[a] > d && size[b] > d)) continue;
    const std::int32_t joined = size[a] + size[b];
    size[pieces.unite(a, b)] = joined;
  }
  std::vector<std::int32_t> number(n, -1), result(n, -1);
  n_aggregates = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!level.active[i]) continue;
    const std::int32_t root = pieces.find(static_cast<std::int32_t>(i));
    if (number[root] < 0) number[root] = static_cast<std::int32_t>(n_aggregates++);
    result[i] = number[root];
  }
  return result;
}

// Adds to `column` (n_modes columns of `rows` entries, column-major) the block of node i's
// rigid modes re-expressed about a point at offset -r from it: a motion t + ω × (x − c) of the
// aggregate is, about the node's position c + r, the motion (t + ω × r) + ω × (x − c − r).
void append_shifted_modes(const NodeLevel& level, std::size_t i, std::span<const double> r, std::size_t row0,
                          std::size_t rows, std::vector<double>& column) {
  const int d = level.dim, m = level.n_modes, k = level.n_unknowns(i);
  // ω × r as a matrix acting on ω: d rows, m − d columns.
  std::array<double, 9> cross{};
  if (d == 3) {
    cross = {0, r[2], -r[1], -r[2], 0, r[0], r[1], -r[0], 0};
  } else {
    cross = {-r[1], r[0]};
  }
  const double* block = level.modes.data() + level.mode_start[i];
  for (int u = 0; u < k; ++u) {
    const double* row = block + static_cast<std::size_t>(u) * m;
    for (int j = 0; j < m; ++j) {
      double value = row[j];
      if (j >= d)
        for (int t = 0; t < d; ++t) value += row[t] * cross[static_cast<std::size_t>(t) * (m - d) + (j - d)];
      column[static_cast<std::size_t>(j) * rows + row0 + u] = value;
    }
  }
}

// The next coarser level, whose node a is aggregate a of `fine`, and the interpolation from it
// to `fine` (zero rows for inactive nodes and for motions the constraints forbid).
NodeLevel coarsen(const NodeLevel& fine, const std::vector<std::int32_t>& aggregate_of, std::size_t n_aggregates,
                  MatHandle& interpolation) {
  const int d = fine.dim, m = fine.n_modes;
  const std::size_t n = fine.size();
  // Members of each aggregate (counting sort).
  std::vector<std::size_t> start(n_aggregates + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (aggregate_of[i] >= 0) ++start[aggregate_of[i] + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::size_t> members(start.back()), fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    if (aggregate_of[i] >= 0) members[fill[aggregate_of[i]]++] = i;

  NodeLevel coarse;
  coarse.dim = d;
  coarse.n_modes = m;
  coarse.position.assign(n_aggregates * d, 0.0);
  coarse.first.assign(n_aggregates + 1, 0);
  coarse.mode_start.assign(n_aggregates + 1, 0);
  coarse.active.assign(n_aggregates, 0);
  std::vector<std::vector<double>> Q(n_aggregates);
  std::vector<std::size_t> rows_of(n_aggregates);
  std::vector<double> block, R;
  for (std::size_t a = 0; a < n_aggregates; ++a) {
    const std::span<const std::size_t> own(members.data() + start[a], start[a + 1] - start[a]);
    std::size_t rows = 0;
    for (std::size_t i : own) {
      for (int k = 0; k < d; ++k) coarse.position[a * d + k] += fine.point(i)[k] / static_cast<double>(own.size());
      rows += static_cast<std::size_t>(fine.n_unknowns(i));
    }
    block.assign(rows * m, 0.0);
    std::size_t row = 0;
    std::array<double, 3> offset{};
    for (std::size_t i : own) {
      for (int k = 0; k < d; ++k) offset[k] = fine.point(i)[k] - coarse.position[a * d + k];
      append_shifted_modes(fine, i, std::span<const double>(offset.data(), d), row, rows, block);
      row += static_cast<std::size_t>(fine.n_unknowns(i));
    }
    Q[a] = orthonormal_columns(block, rows, m, R);
    rows_of[a] = rows;
    const std::size_t k = rows ? Q[a].size() / rows : 0;
    coarse.first[a + 1] = coarse.first[a] + static_cast<PetscInt>(k);
    coarse.mode_start[a + 1] = coarse.mode_start[a] + R.size();
    coarse.modes.insert(coarse.modes.end(), R.begin(), R.end());
    coarse.active[a] = k > 0;
  }
  for (const auto& [i, j] : fine.edges) {
    const std::int32_t a = aggregate_of[i], b = aggregate_of[j];
    if (a >= 0 && b >= 0 && a != b) coarse.edges.emplace_back(std::min(a, b), std::max(a, b));
  }
  std::sort(coarse.edges.begin(), coarse.edges.end());
  coarse.edges.erase(std::unique(coarse.edges.begin(), coarse.edges.end()), coarse.edges.end());

  // Interpolation: the rows of node i (in aggregate a) hold its rows of Q_a.
  const PetscInt n_rows = fine.first.back(), n_columns = coarse.first.back();
  std::vector<PetscInt> nonzeros(static_cast<std::size_t>(n_rows), 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (aggregate_of[i] < 0) continue;
    const std::int32_t a = aggregate_of[i];
    for (PetscInt r = fine.first[i]; r < fine.first[i + 1]; ++r) nonzeros[r] = coarse.n_unknowns(a);
  }
  SNEDE_PETSC(MatCreateSeqAIJ(PETSC_COMM_SELF, n_rows, n_columns, 0, nonzeros.data(), interpolation.out()));
  std::vector<PetscInt> columns;
  std::vector<double> values;
  for (std::size_t a = 0; a < n_aggregates; ++a) {
    const int k = coarse.n_unknowns(a);
    if (k == 0) continue;
    columns.resize(k);
    values.resize(k);
    std::iota(columns.begin(), columns.end(), coarse.first[a]);
    std::size_t row = 0;
    for (std::size_t s = start[a]; s < start[a + 1]; ++s) {
      const std::size_t i = members[s];
      for (PetscInt r = fine.first[i]; r < fine.first[i + 1]; ++r, ++row) {
        for (int p = 0; p < k; ++p) values[p] = Q[a][static_cast<std::size_t>(p) * rows_of[a] + row];
        SNEDE_PETSC(MatSetValues(interpolation, 1, &r, k, columns.data(), values.data(), INSERT_VALUES));
      }
    }
  }
  SNEDE_PETSC(MatAssemblyBegin(interpolation, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(interpolation, MAT_FINAL_ASSEMBLY));
  return coarse;
}

// The first level's interpolation smoothed by one damped Jacobi step of the mesh's graph
// Laplacian (smoothed aggregation with a filtered operator): P = Π (I − ω D⁻¹ L) T, L = L_graph ⊗ I
// with an edge's weight the number of cells that share it, ω = 2/3 (λ_max(D⁻¹L) ≤ 2), Π the
// constraints' projection. The coarse functions then overlap and decay across aggregate
// borders instead of jumping, which is what makes the coarse correction good; L is the mesh's own
// (no edge across a cut), so they still never reach across the lips, and it does not depend
// on the state, so P is made once per mesh and kept through Newton iterations.
MatHandle smoothed_interpolation(const Model& model, const NodeLevel& vertices, Mat tentative) {
  constexpr double omega = 2.0 / 3.0;
  const int d = vertices.dim;
  const std::size_t n = vertices.size();
  std::vector<std::pair<std::int32_t, std::int32_t>> arcs;
  arcs.reserve(2 * vertices.edges.size());
  for (const auto& [i, j] : vertices.edges)
    if (i != j && vertices.active[i] && vertices.active[j]) {
      arcs.emplace_back(i, j);
      arcs.emplace_back(j, i);
    }
  std::sort(arcs.begin(), arcs.end());
  std::vector<std::size_t> start(n + 1, 0);
  for (const auto& arc : arcs) ++start[arc.first + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<PetscInt> nonzeros(n * d, 0);
  std::vector<std::pair<std::int32_t, double>> row;
  for (std::size_t v = 0; v < n; ++v) {
    if (!vertices.active[v]) continue;
    std::size_t distinct = 1;
    for (std::size_t a = start[v]; a < start[v + 1]; ++a) distinct += a == start[v] || arcs[a].second != arcs[a - 1].second;
    for (int k = 0; k < d; ++k) nonzeros[v * d + k] = static_cast<PetscInt>(distinct) * d;
  }
  MatHandle S;
  SNEDE_PETSC(MatCreateSeqAIJ(PETSC_COMM_SELF, static_cast<PetscInt>(n * d), static_cast<PetscInt>(n * d), 0,
                              nonzeros.data(), S.out()));
  std::vector<double> P(static_cast<std::size_t>(d) * d), block(P.size());
  std::vector<PetscInt> rows(d), columns(d);
  for (std::size_t v = 0; v < n; ++v) {
    if (!vertices.active[v]) continue;
    model.constraints().projection_block(static_cast<VertexId>(v), P);
    row.clear();
    for (std::size_t a = start[v]; a < start[v + 1]; ++a) {
      if (row.empty() || row.back().first != arcs[a].second) row.emplace_back(arcs[a].second, 0.0);
      row.back().second += 1.0;
    }
    double degree = 0;
    for (const auto& entry : row) degree += entry.second;
    row.emplace_back(static_cast<std::int32_t>(v), degree);  // the diagonal: 1 − ω after scaling
    for (int k = 0; k < d; ++k) rows[k] = static_cast<PetscInt>(v * d + k);
    for (const auto& [w, weight] : row) {
      const double factor = degree > 0 ? (w == static_cast<std::int32_t>(v) ? 1.0 - omega : omega * weight / degree)
                                       : (w == static_cast<std::int32_t>(v) ? 1.0 : 0.0);
      for (int i = 0; i < d * d; ++i) block[i] = factor * P[i];
      for (int k = 0; k < d; ++k) columns[k] = static_cast<PetscInt>(w) * d + k;
      SNEDE_PETSC(MatSetValues(S, d, rows.data(), d, columns.data(), block.data(), INSERT_VALUES));
    }
  }
  SNEDE_PETSC(MatAssemblyBegin(S, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(S, MAT_FINAL_ASSEMBLY));
  MatHandle smoothed;
  SNEDE_PETSC(MatMatMult(S, tentative, MAT_INITIAL_MATRIX, PETSC_DEFAULT, smoothed.out()));
  return smoothed;
}

std::size_t count_active(const NodeLevel& level) {
  return static_cast<std::size_t>(std::count(level.active.begin(), level.active.end(), 1));
}

}  // namespace

AggregationMultigrid::AggregationMultigrid(Model& fine, int max_levels, bool smooth_first_level, double aggregate_width)
    : GalerkinMultigrid(fine) {
  if (max_levels == 1 || max_levels < 0)
    throw std::invalid_argument("mg needs at least 2 levels (the mesh and a coarser one), got pc_mg_levels " +
                                std::to_string(max_levels));
  if (fine.body().mesh().is_surface())
    throw std::invalid_argument("preconditioner 'mg' works on volume meshes (triangles in 2D, tetrahedra in 3D), "
                                "not on a surface mesh");
  const double mean_edge = mean_edge_length(fine.body().mesh());
  NodeLevel current = vertex_level(fine);
  if (!(aggregate_width > 0) || !std::isfinite(aggregate_width))
    throw std::invalid_argument("mg_aggregate_width must be positive (mean edge lengths), got " +
                                std::to_string(aggregate_width));
  double span = aggregate_width * mean_edge;
  std::vector<Level> finest_first;
  while (max_levels == 0 || static_cast<int>(finest_first.size()) + 1 < max_levels) {
    std::size_t n_aggregates = 0;
    std::vector<std::int32_t> aggregate_of = aggregate(current, span, n_aggregates);
    if (!finest_first.empty() && static_cast<double>(n_aggregates) > least_reduction * static_cast<double>(count_active(current)))
      break;
    Level level;
    level.n_aggregates = n_aggregates;
    NodeLevel coarser = coarsen(current, aggregate_of, n_aggregates, level.interpolation);
    level.n_unknowns = coarser.first.back();
    if (finest_first.empty() && smooth_first_level)
      level.interpolation = smoothed_interpolation(fine, current, level.interpolation);
    finest_first.push_back(std::move(level));
    current = std::move(coarser);
    if (current.first.back() <= direct_unknowns) break;
    span *= span_growth;
  }
  if (max_levels > 0 && static_cast<int>(finest_first.size()) + 1 < max_levels)
    throw std::invalid_argument("pc_mg_levels " + std::to_string(max_levels) + ": aggregating this mesh gives " +
                                std::to_string(finest_first.size() + 1) + " levels before the coarsest is small enough");
  coarse_.assign(std::make_move_iterator(finest_first.rbegin()), std::make_move_iterator(finest_first.rend()));
}

AggregationMultigrid::~AggregationMultigrid() = default;

std::vector<std::size_t> AggregationMultigrid::level_sizes() const {
  std::vector<std::size_t> sizes;
  for (const Level& level : coarse_) sizes.push_back(level.n_aggregates);
  sizes.push_back(fine_.body().mesh().n_cells());
  return sizes;
}

std::vector<std::size_t> AggregationMultigrid::level_unknowns() const {
  std::vector<std::size_t> unknowns;
  for (const Level& level : coarse_) unknowns.push_back(static_cast<std::size_t>(level.n_unknowns));
  unknowns.push_back(static_cast<std::size_t>(fine_.n_dofs()));
  return unknowns;
}

void AggregationMultigrid::configure(PC pc, const SolverOptions& options, const std::vector<double>&) {
  std::vector<Mat> interpolations;
  for (const Level& level : coarse_) interpolations.push_back(level.interpolation);
  configure_levels(pc, std::move(interpolations), options);
}

}  // namespace snede
