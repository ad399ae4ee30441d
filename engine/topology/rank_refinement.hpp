// Conforming bisection (§6.5) of a mesh distributed over ranks (issue 52): each rank bisects
// its own cells, and the ranks tell each other which edges of their common boundary they
// split until no rank has a hanging vertex. Every split made is one that the serial closure
// makes too (an element is split only at its refinement edge, and only when a mark or a split
// edge of a neighbour requires it), so the result is the least conforming refinement of the
// marks, which is the serial one: the same cells as serially, however the body is partitioned.
// The part is refined in place while the ranks stay balanced (the largest at most 1.2 times the
// mean cells, as distribute_cells judges); beyond, DMPlex rebalances the refined cells into a
// new part (distribute_cells).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
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

// What one edit of a PartRefinement reports.
struct RankRefinementReport {
  // `width` values per vertex of the part after the edit (PartRefinement::part(), or
  // `rebalanced`): the field given for the old vertices, new vertices interpolated from their
  // parents (§7.4, as a serial Body's watchers carry state).
  std::vector<double> field;
  // (global id, parent's global id, parent's global id) of the new vertices this rank numbered:
  // every new vertex is listed on exactly one rank.
  std::vector<std::int64_t> new_vertices;
  std::int64_t n_split = 0;  // cells split, over all ranks (as serially)
  // When the refined cells left a rank with more than 1.2 times the mean: the part DMPlex
  // rebalanced them into, and its cells' labels (start a new PartRefinement from them; this one
  // is spent). Otherwise the part was refined in place.
  std::optional<DistributedMesh> rebalanced;
  PartLabels labels;
};

// The refinement of one rank's part, kept from edit to edit so that each costs the cells it
// splits, not the part (collective throughout): the part is copied once, its vertices in the
// order of their global ids (so that ties between equal edges break as in the serial mesh), its
// cells labelled once (or from `labels`, a rebalanced part's), and then refined in place.
class PartRefinement {
 public:
  // Throws the same std::invalid_argument on every rank when `labels` do not fit the part.
  PartRefinement(const DistributedMesh& part, const PartLabels* labels);
  ~PartRefinement();
  PartRefinement(const PartRefinement&) = delete;
  PartRefinement& operator=(const PartRefinement&) = delete;

  // The part as refined so far (its cells and vertices in the copy's order).
  const DistributedMesh& part() const;
  DistributedMesh& part();
  // For each vertex of part() that the given part had: its index there (new vertices follow).
  const std::vector<std::int64_t>& original_vertex() const;
  // After an edit that rebalanced the part: no further edits (std::logic_error).
  bool spent() const;

  // Every cell bisected `levels` times (Bisection::refine_uniform). `field` holds `width`
  // values per vertex of part().
  RankRefinementReport refine_uniform(int levels, std::span<const double> field, int width);
  // Bisected until every cell whose closure contains x has edges no longer than h
  // (refine_around); the same std::invalid_argument on every rank when no rank's cells contain
  // x or h is below round-off there.
  RankRefinementReport refine_around(std::span<const double> x, double h, std::span<const double> field, int width);
  // Bisected until every cell near the segment a–b has edges no longer than h
  // (refine_near_segment); the same std::invalid_argument on every rank when no rank's cells
  // come within `radius` of it or h is below round-off there.
  RankRefinementReport refine_near_segment(std::span<const double> a, std::span<const double> b, double h,
                                           double radius, std::span<const double> field, int width);

 private:
  class State;
  // Marks and splits on each rank (`mark`: the cells split, or std::invalid_argument), then
  // closes across the ranks, until no rank marks any more: the serial loops' fixed point, each
  // mark being one the serial loop makes.
  template <class Mark>
  RankRefinementReport refine_until_unmarked(std::span<const double> field, int width, const std::string& caller,
                                             Mark mark);
  std::unique_ptr<State> state_;
};

}  // namespace snede
