// Interpolations for PCMG over a DistributedMesh: every rank aggregates the vertices it owns
// (grid cells of `aggregate_width` mean edge lengths over the reference positions, connected
// by the rank's mesh edges, as serially: node_aggregation.hpp), so each coarse unknown — a
// rigid motion of an aggregate, projected by the constraints — lives on one rank and the
// interpolation has no off-rank entries. Coarser levels aggregate each rank's aggregates again.
// Aggregates never cross a rank's border, which costs a few more coarse unknowns there but no
// communication to build the levels (the smoothed first level's functions do cross it).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/petsc_handle.hpp"
#include "mesh/distributed_mesh.hpp"
#include "problem/constraints.hpp"
#include "multigrid/node_aggregation.hpp"

namespace snede {

struct RankAggregationLevels {
  std::vector<MatHandle> interpolations;   // coarsest first; each from a level to the next finer (MPIAIJ)
  std::vector<PetscInt> global_unknowns;   // per level, coarsest first, the fine level last
};

// Collective on part.comm, with the same arguments on every rank. constraints: the problem's,
// on the rank's local vertices (owned and ghost): each coarse unknown is a rigid motion of an
// aggregate projected by its vertices' P (a fixed vertex allows none, a sliding one only
// motions along its line). The fine level's rows are the problem's: owned vertices' dofs at
// rows global_number[v]*dim + k (contiguous per rank, in the order of VecCreateMPI with
// n_owned*dim local rows). Stops when the coarsest level has at most `direct_unknowns` unknowns
// over all ranks or coarsening would keep more than 60 % of the nodes, or at max_levels
// counting the fine one (0: no limit); at least 2 levels. A rank that owns no vertex has no
// coarse unknowns. Throws std::invalid_argument (the same on every rank) for a surface mesh
// (preconditioner "mg" is for volume meshes), a width that is not positive, max_levels 1 or
// negative, or constraints of another size than the rank's vertices on some rank.
// smooth_first_level: every level's interpolation is smoothed (smoothed_aggregation.hpp; the
// coarse functions then reach into the neighbouring ranks' vertices).
RankAggregationLevels rank_aggregation_levels(const DistributedMesh& part, const Constraints& constraints,
                                              double aggregate_width, int max_levels = 0,
                                              PetscInt direct_unknowns = default_direct_unknowns,
                                              bool smooth_first_level = false);

// The same with whole dofs fixed: fixed_local, per local dof (n_local_vertices × dim), is 1
// where the dof is fixed.
RankAggregationLevels rank_aggregation_levels(const DistributedMesh& part, std::span<const std::uint8_t> fixed_local,
                                              double aggregate_width, int max_levels = 0,
                                              PetscInt direct_unknowns = default_direct_unknowns,
                                              bool smooth_first_level = false);

}  // namespace snede
