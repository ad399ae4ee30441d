#include "multigrid/aggregation_multigrid.hpp"

#include <algorithm>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "multigrid/coarse_basis.hpp"
#include "multigrid/node_aggregation.hpp"

namespace snede {
namespace {

// The mesh's vertices as the finest level, node v for vertex v, with the translations the
// model's constraints allow.
NodeLevel model_vertex_level(const Model& model) {
  const Mesh& mesh = model.body().mesh();
  std::vector<std::int32_t> node_of(static_cast<std::size_t>(mesh.n_points()));
  std::iota(node_of.begin(), node_of.end(), 0);
  return vertex_level(mesh, node_of, node_of.size(), [&model](VertexId v, std::span<double> projection) {
    model.constraints().projection_block(v, projection);
  });
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

}  // namespace

AggregationMultigrid::AggregationMultigrid(Model& fine, int max_levels, bool smooth_first_level, double aggregate_width)
    : GalerkinMultigrid(fine) {
  check_level_limit(max_levels);
  if (fine.body().mesh().is_surface())
    throw std::invalid_argument("preconditioner 'mg' works on volume meshes (triangles in 2D, tetrahedra in 3D), "
                                "not on a surface mesh");
  check_aggregate_width(aggregate_width);
  const NodeLevel vertices = model_vertex_level(fine);
  std::vector<AggregateLevel> finest_first =
      aggregate_levels(vertices, aggregate_width * mean_edge_length(fine.body().mesh()), max_levels,
                       default_direct_unknowns, PETSC_COMM_SELF);
  if (smooth_first_level)
    finest_first.front().interpolation = smoothed_interpolation(fine, vertices, finest_first.front().interpolation);
  if (max_levels > 0 && static_cast<int>(finest_first.size()) + 1 < max_levels)
    throw std::invalid_argument("pc_mg_levels " + std::to_string(max_levels) + ": aggregating this mesh gives " +
                                std::to_string(finest_first.size() + 1) + " levels before the coarsest is small enough");
  for (auto level = finest_first.rbegin(); level != finest_first.rend(); ++level)
    coarse_.push_back(Level{level->n_aggregates, level->n_unknowns, std::move(level->interpolation)});
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
