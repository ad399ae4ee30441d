// Where the preconditioner "mg" takes its levels from, for one kind of problem, as PCMG takes
// its coarsening from a DM: a serial model's mesh (coarser bisection meshes, a background grid
// or aggregates) or a distributed problem's ranks (aggregates of each rank's vertices). The
// static solver asks it whether the problem has levels at all, and for new levels after each
// change of the mesh; which source a problem has is fixed where the solver is made, not found
// out by casting the problem.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "core/solver_options.hpp"
#include "multigrid/multigrid.hpp"
#include "problem/distributed_static.hpp"
#include "problem/model.hpp"
#include "topology/refinement_hierarchy.hpp"

namespace snede {

class LevelSource {
 public:
  virtual ~LevelSource() = default;
  // Whether "mg" has levels for the problem.
  virtual bool has_levels() const = 0;
  // Levels for the problem as it is now, configured by the options under `prefix` (the solver's,
  // without '-'): -<prefix>mg_coarsening, pc_mg_levels (a limit), mg_grid_width,
  // mg_aggregate_width, mg_aggregation_smoothing. `earlier`: the levels of the mesh before an
  // edit, which grid levels follow when they can; `rebuild_after_edits`: made from scratch
  // whatever the earlier ones (the reference of issue 49, item 7). std::invalid_argument for an
  // option that does not apply to the levels made.
  virtual std::unique_ptr<Multigrid> make_levels(const SolverOptions& options, const std::string& prefix,
                                                 Multigrid* earlier, bool rebuild_after_edits) = 0;
  // The mesh's bisection hierarchy, once it has one: the next levels coarsen along it.
  virtual void use_hierarchy(const RefinementHierarchy* /*hierarchy*/) {}
  // How many levels were made from the earlier ones after an edit.
  virtual std::size_t levels_edited() const { return 0; }
};

// Levels of a serial model: bisection levels when the hierarchy (may be null; it must outlive
// the source) gives a small enough coarsest mesh, else a grid, or aggregation when asked.
std::unique_ptr<LevelSource> mesh_level_source(Model& model, const RefinementHierarchy* hierarchy);
// Aggregation levels on each rank's vertices (volume meshes only).
std::unique_ptr<LevelSource> rank_level_source(DistributedStatic& problem);

}  // namespace snede
