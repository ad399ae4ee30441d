#include "multigrid/rank_aggregation.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/rank_agreement.hpp"
#include "multigrid/coarse_basis.hpp"
#include "multigrid/smoothed_aggregation.hpp"

namespace snede {
namespace {

// The mean edge length over every rank's cells (each rank's mean weighted by its cells).
double global_mean_edge_length(const DistributedMesh& part) {
  double local[2] = {mean_edge_length(*part.local) * static_cast<double>(part.local->n_cells()),
                     static_cast<double>(part.local->n_cells())};
  double global[2] = {0, 0};
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_SUM, part.comm);
  return global[1] > 0 ? global[0] / global[1] : 0.0;
}

// The rank's owned vertices as the finest level, node i the owned vertex PETSc numbers
// (the rank's first number) + i, so that node i's unknowns are the rank's rows i·dim ...; each
// vertex's motions projected by `projection`.
NodeLevel owned_vertex_level(const DistributedMesh& part, const VertexProjection& projection) {
  std::int64_t first_number = std::numeric_limits<std::int64_t>::max();
  std::size_t n_owned = 0;
  for (std::size_t v = 0; v < part.owned.size(); ++v)
    if (part.owned[v]) {
      first_number = std::min(first_number, part.global_number[v]);
      ++n_owned;
    }
  std::vector<std::int32_t> node_of(part.owned.size(), -1);
  for (std::size_t v = 0; v < part.owned.size(); ++v) {
    if (!part.owned[v]) continue;
    const std::int64_t node = part.global_number[v] - first_number;
    if (node < 0 || node >= static_cast<std::int64_t>(n_owned))
      throw std::logic_error("rank_aggregation_levels: PETSc's numbering of the owned vertices is not contiguous");
    node_of[v] = static_cast<std::int32_t>(node);
  }
  return vertex_level(*part.local, node_of, n_owned, projection);
}

// The levels over `projection`; `misfit` says why the projection does not fit this rank's
// vertices (empty when it does).
RankAggregationLevels levels_over(const DistributedMesh& part, const VertexProjection& projection,
                                  const std::string& misfit, double aggregate_width, int max_levels,
                                  PetscInt direct_unknowns, bool smooth_first_level) {
  const Mesh& mesh = *part.local;
  // After this every rank takes the same branch below: the checks throw on all ranks or none.
  RankAgreement("rank_aggregation_levels")
      .input("aggregate_width", aggregate_width)
      .input("max_levels", static_cast<double>(max_levels))
      .input("direct_unknowns", static_cast<double>(direct_unknowns))
      .input("smooth_first_level", static_cast<double>(smooth_first_level))
      .input("constraints fit the rank's vertices", static_cast<double>(misfit.empty()))
      .require(part.comm);
  if (!misfit.empty()) throw std::invalid_argument("rank_aggregation_levels: " + misfit);
  check_level_limit(max_levels);
  if (mesh.is_surface())
    throw std::invalid_argument("preconditioner 'mg' on MPI ranks (rank_aggregation_levels) works on volume meshes "
                                "(triangles in 2D, tetrahedra in 3D), not on a membrane (surface mesh); use 'gamg', "
                                "'bjacobi', 'jacobi' or 'none'");
  check_aggregate_width(aggregate_width);

  const NodeLevel vertices = owned_vertex_level(part, projection);
  std::vector<AggregateLevel> finest_first = aggregate_levels(
      vertices, aggregate_width * global_mean_edge_length(part), max_levels, direct_unknowns, part.comm);
  if (smooth_first_level) {
    std::vector<VertexId> owned_local;  // the owned vertices' local ids, in their rows' order
    for (std::size_t v = 0; v < part.owned.size(); ++v)
      if (part.owned[v]) owned_local.push_back(static_cast<VertexId>(v));
    std::sort(owned_local.begin(), owned_local.end(),
              [&](VertexId a, VertexId b) { return part.global_number[a] < part.global_number[b]; });
    const MatHandle adjacency =
        cell_edge_adjacency(part.comm, mesh, part.global_number, static_cast<PetscInt>(owned_local.size()));
    smooth_interpolations(adjacency, mesh.dim(), owned_local, projection, finest_first, true);
  }
  RankAggregationLevels levels;
  for (auto level = finest_first.rbegin(); level != finest_first.rend(); ++level) {
    PetscInt rows = 0, columns = 0;
    SNEDE_PETSC(MatGetSize(level->interpolation, &rows, &columns));
    levels.global_unknowns.push_back(columns);
    levels.interpolations.push_back(std::move(level->interpolation));
  }
  levels.global_unknowns.push_back(static_cast<PetscInt>(part.n_global_vertices) * mesh.dim());
  return levels;
}

}  // namespace

RankAggregationLevels rank_aggregation_levels(const DistributedMesh& part, const Constraints& constraints,
                                              double aggregate_width, int max_levels, PetscInt direct_unknowns,
                                              bool smooth_first_level) {
  const Mesh& mesh = *part.local;
  const bool fits = constraints.n_points() == mesh.n_points() && constraints.dim() == mesh.dim();
  const std::string misfit = fits ? "" : "the constraints have " + std::to_string(constraints.n_points()) +
                                             " vertices in " + std::to_string(constraints.dim()) + "D, the rank has " +
                                             std::to_string(mesh.n_points()) + " in " + std::to_string(mesh.dim()) + "D";
  return levels_over(
      part, [&](VertexId v, std::span<double> block) { constraints.projection_block(v, block); }, misfit,
      aggregate_width, max_levels, direct_unknowns, smooth_first_level);
}

RankAggregationLevels rank_aggregation_levels(const DistributedMesh& part, std::span<const std::uint8_t> fixed_local,
                                              double aggregate_width, int max_levels, PetscInt direct_unknowns,
                                              bool smooth_first_level) {
  const int d = part.local->dim();
  const std::size_t n_local_dofs = static_cast<std::size_t>(part.local->n_points()) * static_cast<std::size_t>(d);
  const std::string misfit = fixed_local.size() == n_local_dofs
                                 ? ""
                                 : "fixed_local has " + std::to_string(fixed_local.size()) +
                                       " values, the rank's vertices have " + std::to_string(n_local_dofs) + " dofs";
  // A fixed dof allows no translation along its axis.
  const auto projection = [&](VertexId v, std::span<double> block) {
    std::fill(block.begin(), block.end(), 0.0);
    for (int k = 0; k < d; ++k)
      block[static_cast<std::size_t>(k) * d + k] = fixed_local[static_cast<std::size_t>(v) * d + k] ? 0.0 : 1.0;
  };
  return levels_over(part, projection, misfit, aggregate_width, max_levels, direct_unknowns, smooth_first_level);
}

}  // namespace snede
