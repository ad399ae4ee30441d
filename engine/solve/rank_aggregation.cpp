#include "solve/rank_aggregation.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/rank_agreement.hpp"
#include "solve/coarse_basis.hpp"

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
// (the rank's first number) + i, so that node i's unknowns are the rank's rows i·dim ...;
// a fixed dof allows no translation along its axis.
NodeLevel owned_vertex_level(const DistributedMesh& part, std::span<const std::uint8_t> fixed_local) {
  const Mesh& mesh = *part.local;
  const int d = mesh.dim();
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
  return vertex_level(mesh, node_of, n_owned, [&](VertexId v, std::span<double> projection) {
    std::fill(projection.begin(), projection.end(), 0.0);
    for (int k = 0; k < d; ++k)
      projection[static_cast<std::size_t>(k) * d + k] = fixed_local[static_cast<std::size_t>(v) * d + k] ? 0.0 : 1.0;
  });
}

}  // namespace

RankAggregationLevels rank_aggregation_levels(const DistributedMesh& part, std::span<const std::uint8_t> fixed_local,
                                              double aggregate_width, int max_levels, PetscInt direct_unknowns) {
  const Mesh& mesh = *part.local;
  const std::size_t n_local_dofs = static_cast<std::size_t>(mesh.n_points()) * static_cast<std::size_t>(mesh.dim());
  // After this every rank takes the same branch below: the checks throw on all ranks or none.
  RankAgreement("rank_aggregation_levels")
      .input("aggregate_width", aggregate_width)
      .input("max_levels", static_cast<double>(max_levels))
      .input("direct_unknowns", static_cast<double>(direct_unknowns))
      .input("fixed_local has a value per local dof", static_cast<double>(fixed_local.size() == n_local_dofs))
      .require(part.comm);
  if (fixed_local.size() != n_local_dofs)
    throw std::invalid_argument("rank_aggregation_levels: fixed_local has " + std::to_string(fixed_local.size()) +
                                " values, the rank's vertices have " + std::to_string(n_local_dofs) + " dofs");
  check_level_limit(max_levels);
  if (mesh.is_surface())
    throw std::invalid_argument("rank_aggregation_levels: aggregates volume meshes (triangles in 2D, tetrahedra in "
                                "3D), not a surface mesh");
  check_aggregate_width(aggregate_width);

  const NodeLevel vertices = owned_vertex_level(part, fixed_local);
  std::vector<AggregateLevel> finest_first = aggregate_levels(
      vertices, aggregate_width * global_mean_edge_length(part), max_levels, direct_unknowns, part.comm);
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

}  // namespace snede
