// Aggregating nodes with their rigid modes: the level-building of aggregation multigrid
// (aggregation_multigrid.hpp, serial; rank_aggregation.hpp, over a distributed mesh). The
// nodes of a level are grouped in aggregates (one cell of a grid over the reference positions,
// connected by the mesh's edges inside it); each aggregate's rigid modes, projected by the
// constraints, orthonormalised, are the next level's unknowns and the interpolation's columns.
// Internal to the solvers.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "core/petsc_handle.hpp"
#include "mesh/mesh.hpp"

namespace snede {

// Each coarser level's cells are this much wider.
constexpr double aggregate_span_growth = 2.0;
// Coarsening stops once a level has at most this many unknowns: its LU is then cheap...
constexpr PetscInt default_direct_unknowns = 1500;
// ...or when aggregating would keep more than this fraction of the nodes (a level that hardly
// coarsens costs a smoother without reducing the problem).
constexpr double least_aggregate_reduction = 0.6;

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

// The translations a vertex's constraints allow: the dim × dim projection (row-major) into `block`.
using VertexProjection = std::function<void(VertexId, std::span<double> block)>;

// The mesh's vertices as the finest level of `n_nodes` nodes, node_of[v] for vertex v (−1: the
// vertex is no node) with unknowns dim × node; a node without a live vertex is inactive. About its
// own position a rotation does not move a vertex: its modes are the translations `projection` allows.
NodeLevel vertex_level(const Mesh& mesh, std::span<const std::int32_t> node_of, std::size_t n_nodes,
                       const VertexProjection& projection);

// Per node its aggregate (-1 for an inactive node): the nodes in one cell of a grid of width
// `span` that the level's edges join inside that cell; a piece of fewer than dim + 1 nodes
// joins a piece it shares an edge with (it would barely coarsen). Pieces never join across a
// missing edge, so what a cut separated stays separate.
std::vector<std::int32_t> aggregate(const NodeLevel& level, double span, std::size_t& n_aggregates);

// Collective on `comm`. The next coarser level, whose node a is aggregate a of `fine`, and the
// interpolation from it to `fine` (zero rows for inactive nodes and for motions the constraints
// forbid): an AIJ matrix on `comm` whose rows on this rank are this rank's fine unknowns and
// whose columns are its coarse ones, so no entry is off the rank's diagonal block.
NodeLevel coarsen(const NodeLevel& fine, const std::vector<std::int32_t>& aggregate_of, std::size_t n_aggregates,
                  MPI_Comm comm, MatHandle& interpolation);

std::size_t count_active(const NodeLevel& level);

struct AggregateLevel {
  std::size_t n_aggregates = 0;  // this rank's
  PetscInt n_unknowns = 0;       // this rank's
  MatHandle interpolation;       // from this level to the next finer one
};

// Collective on `comm`: the coarser levels of `finest` (this rank's nodes), finest first, each
// aggregating the one before on a grid `aggregate_span_growth` times wider, starting at width
// `span`. At least one; stops when the coarsest has at most `direct_unknowns` unknowns, when
// the next would keep more than `least_aggregate_reduction` of the nodes (both counted over the
// ranks), or at `max_levels` levels counting the fine one (0: no limit).
std::vector<AggregateLevel> aggregate_levels(const NodeLevel& finest, double span, int max_levels,
                                             PetscInt direct_unknowns, MPI_Comm comm);

// Throws std::invalid_argument unless `width` (mean edge lengths) is positive and finite.
void check_aggregate_width(double width);
// Throws std::invalid_argument for max_levels 1 or negative (0: no limit).
void check_level_limit(int max_levels);

}  // namespace snede
