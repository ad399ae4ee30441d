// Conforming bisection (§6.5) of a mesh distributed over ranks (issue 52): each rank bisects
// its own cells, and the ranks tell each other which edges of their common boundary they
// split until no rank has a hanging vertex. Every split made is one that the serial closure
// makes too (an element is split only at its refinement edge, and only when a mark or a split
// edge of a neighbour requires it), so the result is the least conforming refinement of the
// marks, which is the serial one: the same cells as serially, however the body is partitioned.
// The refined cells go to a new part through distribute_cells, which keeps balanced parts and
// has DMPlex rebalance them when the largest rank holds more than 1.2 times the mean.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mesh/distributed_mesh.hpp"
#include "topology/initial_labelling.hpp"

namespace snede {

// The bisection labels of a part's cells (§6.5), kept from one refinement to the next so that
// it goes on as the serial hierarchy does: relabelling a refined Kuhn box afresh would lose
// Maubach's tags and bisect it otherwise (more cells from the third level on).
struct PartLabels {
  BisectionRule rule = BisectionRule::newest_vertex;
  // Per cell of part.local, in its row order: the cell's global vertex ids in label order
  // (x0..xd), then the tag.
  std::vector<std::int64_t> cells;
};

struct RefinedPart {
  DistributedMesh part;
  // `width` values per vertex of the new part: the field given for the old vertices, new
  // vertices interpolated from their parents (§7.4, as a serial Body's watchers carry state).
  std::vector<double> field;
  // (global id, parent's global id, parent's global id) of the new vertices this rank numbered:
  // every new vertex is listed on exactly one rank.
  std::vector<std::int64_t> new_vertices;
  std::int64_t n_split = 0;  // cells split, over all ranks (as serially)
  PartLabels labels;         // of the new part's cells, for the next refinement
};

// Collective. Every cell bisected `levels` times (Bisection::refine_uniform). `field` holds
// `width` values per vertex of part.local; `labels` are those the part's previous refinement
// gave (nullptr: a part never refined, labelled as serially). Labels that do not fit the part's
// cells throw the same std::invalid_argument on every rank.
RefinedPart refine_part_uniform(const DistributedMesh& part, int levels, std::span<const double> field, int width,
                                const PartLabels* labels);

// Collective. Bisected until every cell whose closure contains x has edges no longer than h
// (refine_around). Throws the same std::invalid_argument on every rank when no rank's cells
// contain x or h is below round-off there.
RefinedPart refine_part_around(const DistributedMesh& part, std::span<const double> x, double h,
                               std::span<const double> field, int width, const PartLabels* labels);

// Collective. Bisected until every cell near the segment a–b has edges no longer than h
// (refine_near_segment); the same std::invalid_argument on every rank when no rank's cells come
// within `radius` of it or h is below round-off there.
RefinedPart refine_part_near_segment(const DistributedMesh& part, std::span<const double> a, std::span<const double> b,
                                     double h, double radius, std::span<const double> field, int width,
                                     const PartLabels* labels);

}  // namespace snede
