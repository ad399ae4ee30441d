#include "multigrid/node_aggregation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "multigrid/coarse_basis.hpp"

namespace snede {
namespace {

// Grid cells are numbered in 21 bits per direction.
constexpr double max_cells_per_direction = 1 << 20;

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

std::uint64_t sum_over_ranks(MPI_Comm comm, std::uint64_t value) {
  std::uint64_t sum = 0;
  MPI_Allreduce(&value, &sum, 1, MPI_UINT64_T, MPI_SUM, comm);
  return sum;
}

}  // namespace

NodeLevel vertex_level(const Mesh& mesh, std::span<const std::int32_t> node_of, std::size_t n_nodes,
                       const VertexProjection& projection) {
  const int d = mesh.dim();
  NodeLevel level;
  level.dim = d;
  level.n_modes = d == 3 ? 6 : 3;
  level.position.assign(n_nodes * d, 0.0);
  level.first.resize(n_nodes + 1);
  level.mode_start.resize(n_nodes + 1);
  level.active.assign(n_nodes, 0);
  level.modes.assign(n_nodes * d * level.n_modes, 0.0);
  std::vector<double> P(static_cast<std::size_t>(d) * d);
  for (std::size_t i = 0; i <= n_nodes; ++i) {
    level.first[i] = static_cast<PetscInt>(i * d);
    level.mode_start[i] = i * d * level.n_modes;
  }
  const std::vector<double>& points = mesh.points();
  for (VertexId v = 0; v < static_cast<VertexId>(node_of.size()); ++v) {
    const std::int32_t i = node_of[v];
    if (i < 0) continue;
    std::copy_n(points.begin() + static_cast<std::ptrdiff_t>(v) * d, d, level.position.begin() + static_cast<std::ptrdiff_t>(i) * d);
    level.active[i] = mesh.is_vertex(v);
    if (!level.active[i]) continue;
    projection(v, P);
    for (int r = 0; r < d; ++r)
      for (int c = 0; c < d; ++c) level.modes[level.mode_start[i] + static_cast<std::size_t>(r) * level.n_modes + c] = P[r * d + c];
  }
  const std::vector<VertexId> cells = mesh.cells();
  const int nv = mesh.cell_dim() + 1;
  level.edges.reserve(cells.size() / nv * nv * (nv - 1) / 2);
  for (std::size_t c = 0; c < cells.size(); c += nv)
    for (int a = 0; a < nv; ++a)
      for (int b = a + 1; b < nv; ++b) {
        const std::int32_t i = node_of[cells[c + a]], j = node_of[cells[c + b]];
        if (i >= 0 && j >= 0) level.edges.emplace_back(std::min(i, j), std::max(i, j));
      }
  return level;
}

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

NodeLevel coarsen(const NodeLevel& fine, const std::vector<std::int32_t>& aggregate_of, std::size_t n_aggregates,
                  MPI_Comm comm, MatHandle& interpolation) {
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

  // Interpolation: the rows of node i (in aggregate a) hold its rows of Q_a, shifted to the
  // rank's rows and columns.
  const PetscInt n_rows = fine.first.back(), n_columns = coarse.first.back();
  std::vector<PetscInt> nonzeros(static_cast<std::size_t>(n_rows), 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (aggregate_of[i] < 0) continue;
    const std::int32_t a = aggregate_of[i];
    for (PetscInt r = fine.first[i]; r < fine.first[i + 1]; ++r) nonzeros[r] = coarse.n_unknowns(a);
  }
  SNEDE_PETSC(MatCreateAIJ(comm, n_rows, n_columns, PETSC_DETERMINE, PETSC_DETERMINE, 0, nonzeros.data(), 0, nullptr,
                           interpolation.out()));
  PetscInt row_start = 0, row_end = 0, column_start = 0, column_end = 0;
  SNEDE_PETSC(MatGetOwnershipRange(interpolation, &row_start, &row_end));
  SNEDE_PETSC(MatGetOwnershipRangeColumn(interpolation, &column_start, &column_end));
  std::vector<PetscInt> columns;
  std::vector<double> values;
  for (std::size_t a = 0; a < n_aggregates; ++a) {
    const int k = coarse.n_unknowns(a);
    if (k == 0) continue;
    columns.resize(k);
    values.resize(k);
    std::iota(columns.begin(), columns.end(), column_start + coarse.first[a]);
    std::size_t row = 0;
    for (std::size_t s = start[a]; s < start[a + 1]; ++s) {
      const std::size_t i = members[s];
      for (PetscInt r = fine.first[i]; r < fine.first[i + 1]; ++r, ++row) {
        for (int p = 0; p < k; ++p) values[p] = Q[a][static_cast<std::size_t>(p) * rows_of[a] + row];
        const PetscInt global_row = row_start + r;
        SNEDE_PETSC(MatSetValues(interpolation, 1, &global_row, k, columns.data(), values.data(), INSERT_VALUES));
      }
    }
  }
  SNEDE_PETSC(MatAssemblyBegin(interpolation, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(interpolation, MAT_FINAL_ASSEMBLY));
  return coarse;
}

std::size_t count_active(const NodeLevel& level) {
  return static_cast<std::size_t>(std::count(level.active.begin(), level.active.end(), 1));
}

std::vector<AggregateLevel> aggregate_levels(const NodeLevel& finest, double span, int max_levels,
                                             PetscInt direct_unknowns, MPI_Comm comm) {
  std::vector<AggregateLevel> finest_first;
  const NodeLevel* current = &finest;
  NodeLevel coarsest;
  while (max_levels == 0 || static_cast<int>(finest_first.size()) + 1 < max_levels) {
    AggregateLevel level;
    std::vector<std::int32_t> aggregate_of = aggregate(*current, span, level.n_aggregates);
    if (!finest_first.empty() && static_cast<double>(sum_over_ranks(comm, level.n_aggregates)) >
                                     least_aggregate_reduction * static_cast<double>(sum_over_ranks(comm, count_active(*current))))
      break;
    NodeLevel coarser = coarsen(*current, aggregate_of, level.n_aggregates, comm, level.interpolation);
    level.n_unknowns = coarser.first.back();
    finest_first.push_back(std::move(level));
    coarsest = std::move(coarser);
    current = &coarsest;
    if (sum_over_ranks(comm, static_cast<std::uint64_t>(current->first.back())) <= static_cast<std::uint64_t>(direct_unknowns))
      break;
    span *= aggregate_span_growth;
  }
  return finest_first;
}

void check_aggregate_width(double width) {
  if (!(width > 0) || !std::isfinite(width))
    throw std::invalid_argument("mg_aggregate_width must be positive (mean edge lengths), got " + std::to_string(width));
}

void check_level_limit(int max_levels) {
  if (max_levels == 1 || max_levels < 0)
    throw std::invalid_argument("mg needs at least 2 levels (the mesh and a coarser one), got pc_mg_levels " +
                                std::to_string(max_levels));
}

}  // namespace snede
