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
#include "multigrid/smoothed_aggregation.hpp"

namespace snede {
namespace {

// The mesh's vertices as the finest level, node v for vertex v, with the translations the
// model's constraints allow (`projection`).
NodeLevel model_vertex_level(const Model& model, const VertexProjection& projection) {
  const Mesh& mesh = model.body().mesh();
  std::vector<std::int32_t> node_of(static_cast<std::size_t>(mesh.n_points()));
  std::iota(node_of.begin(), node_of.end(), 0);
  return vertex_level(mesh, node_of, node_of.size(), projection);
}

}  // namespace

AggregationMultigrid::AggregationMultigrid(Model& fine, int max_levels, bool smooth_first_level, double aggregate_width)
    : GalerkinMultigrid(fine) {
  check_level_limit(max_levels);
  if (fine.body().mesh().is_surface())
    throw std::invalid_argument("preconditioner 'mg' works on volume meshes (triangles in 2D, tetrahedra in 3D), "
                                "not on a surface mesh");
  check_aggregate_width(aggregate_width);
  const VertexProjection projection = [&fine](VertexId v, std::span<double> block) {
    fine.constraints().projection_block(v, block);
  };
  const NodeLevel vertices = model_vertex_level(fine, projection);
  std::vector<AggregateLevel> finest_first =
      aggregate_levels(vertices, aggregate_width * mean_edge_length(fine.body().mesh()), max_levels,
                       default_direct_unknowns, PETSC_COMM_SELF);
  if (smooth_first_level) {
    const Mesh& mesh = fine.body().mesh();
    std::vector<std::int64_t> row_of_vertex(static_cast<std::size_t>(mesh.n_points()));
    std::iota(row_of_vertex.begin(), row_of_vertex.end(), 0);
    std::vector<VertexId> vertex_of_row(row_of_vertex.begin(), row_of_vertex.end());
    const MatHandle adjacency =
        cell_edge_adjacency(PETSC_COMM_SELF, mesh, row_of_vertex, static_cast<PetscInt>(row_of_vertex.size()));
    smooth_interpolations(adjacency, mesh.dim(), vertex_of_row, projection, finest_first, true);
  }
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
