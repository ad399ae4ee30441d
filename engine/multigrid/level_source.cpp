#include "multigrid/level_source.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <utility>

#include "core/log_event.hpp"
#include "multigrid/aggregation_multigrid.hpp"
#include "multigrid/bisection_multigrid.hpp"
#include "multigrid/grid_multigrid.hpp"
#include "multigrid/rank_aggregation_multigrid.hpp"

namespace snede {
namespace {

// The options every source reads: how the levels are made and how many at most.
struct LevelSettings {
  std::string flag;  // "-" and the solver's prefix, for messages
  std::string coarsening;  // auto, bisection, aggregation or grid
  int max_levels = 0;  // 0: as many as the coarsening gives
};

LevelSettings read_settings(const SolverOptions& options, const std::string& prefix) {
  LevelSettings settings{"-" + prefix, options.string_option(prefix + "mg_coarsening").value_or("auto"), 0};
  const std::string& flag = settings.flag;
  const std::optional<std::string> galerkin = options.string_option(prefix + "pc_mg_galerkin");
  if (galerkin && *galerkin != "none" && *galerkin != "false" && *galerkin != "0")
    throw std::invalid_argument(flag + "pc_mg_galerkin: 'mg' chooses its coarse operators itself (the levels' "
                                "own shells on a bisection hierarchy, Galerkin products on grid or aggregation levels)");
  // PCMG's own -pc_mg_levels would replace the levels configured here: it limits them instead.
  if (const std::optional<std::string> levels = options.string_option(prefix + "pc_mg_levels")) {
    try {
      std::size_t used = 0;
      settings.max_levels = std::stoi(*levels, &used);
      if (used != levels->size()) throw std::invalid_argument(*levels);
    } catch (const std::exception&) {
      throw std::invalid_argument(flag + "pc_mg_levels must be an integer, got '" + *levels + "'");
    }
    if (settings.max_levels < 2)
      throw std::invalid_argument("mg needs at least 2 levels (the mesh and a coarser one), got " + flag +
                                  "pc_mg_levels " + *levels);
  }
  const std::string& coarsening = settings.coarsening;
  if (coarsening != "auto" && coarsening != "bisection" && coarsening != "aggregation" && coarsening != "grid")
    throw std::invalid_argument(flag + "mg_coarsening must be auto, bisection, aggregation or grid, got '" +
                                coarsening + "'");
  return settings;
}

double aggregate_width(const SolverOptions& options, const std::string& prefix) {
  return options.number_option(prefix + "mg_aggregate_width", AggregationMultigrid::default_aggregate_width);
}

// Whether a hierarchy's coarsest level is small enough for its direct solve: at most a
// sixteenth of the fine level (in cells or in unknowns), about as large as the grid levels'
// (4 vertex spacings wide: a 64th of the vertices, with up to d unknowns per node copy), or a
// thousand.
bool small_coarsest_level(std::size_t coarsest, std::size_t fine) {
  return coarsest <= std::max<std::size_t>(1000, fine / 16);
}

class MeshLevelSource final : public LevelSource {
 public:
  MeshLevelSource(Model& model, const RefinementHierarchy* hierarchy) : model_(model), hierarchy_(hierarchy) {}

  bool has_levels() const override { return true; }

  void use_hierarchy(const RefinementHierarchy* hierarchy) override {
    if (hierarchy != hierarchy_) bisection_refused_at_splits_.reset();
    hierarchy_ = hierarchy;
  }

  std::size_t levels_edited() const override { return levels_edited_; }

  std::unique_ptr<Multigrid> make_levels(const SolverOptions& options, const std::string& prefix, Multigrid* earlier,
                                         bool rebuild_after_edits) override {
    const LevelSettings settings = read_settings(options, prefix);
    if (settings.coarsening == "bisection" && !hierarchy_)
      throw std::invalid_argument(settings.flag + "mg_coarsening bisection: this mesh has no bisection hierarchy "
                                  "(refine it with mesh.refine_uniform or refine_around first, or use grid or "
                                  "aggregation)");
    std::unique_ptr<Multigrid> levels = bisection_levels(settings);
    if (!levels && settings.coarsening != "aggregation")
      levels = grid_levels(settings, options, prefix, earlier, rebuild_after_edits);
    if (!levels)
      levels = std::make_unique<AggregationMultigrid>(
          model_, settings.max_levels, options.bool_option(prefix + "mg_aggregation_smoothing", false),
          aggregate_width(options, prefix));
    refuse_options_of_other_levels(*levels, settings, options, prefix);
    return levels;
  }

 private:
  // Levels from coarser bisection meshes when the hierarchy gives them (with a small coarsest
  // mesh, under "auto"), else null.
  std::unique_ptr<Multigrid> bisection_levels(const LevelSettings& settings) {
    const std::string& coarsening = settings.coarsening;
    if (coarsening == "aggregation" || coarsening == "grid" || !hierarchy_) return nullptr;
    // A mesh read from a file and refined locally (along a needle) has that mesh, or more, as the
    // coarsest bisection level: a direct solve on it costs more than the grid levels (a
    // 21k-tetrahedron liver took 1.6 s per factorisation). Its roots tell before the levels are made.
    const bool small_roots = small_coarsest_level(hierarchy_->roots().size(), model_.body().mesh().n_cells());
    const bool refused_before = coarsening == "auto" && bisection_refused_at_splits_ == hierarchy_->n_splits();
    if (!(small_roots || coarsening == "bisection") || refused_before) return nullptr;
    std::unique_ptr<Multigrid> levels;
    try {
      static const PetscLogEvent event = log_event("SnedeBisectionLevels");
      ScopedEvent logged(event);
      levels = std::make_unique<BisectionMultigrid>(model_, *hierarchy_, settings.max_levels);
      const std::vector<std::size_t> unknowns = levels->level_unknowns();
      if (coarsening == "auto" && !small_coarsest_level(unknowns.front(), unknowns.back())) levels.reset();
    } catch (const std::invalid_argument&) {
      // No conforming coarser cut (a mesh never refined, or one that was cut or flipped since):
      // any mesh can be coarsened on its own.
      if (coarsening == "bisection") throw;
    }
    // A cut, a flip or a collapse only takes elements out of the tree (into new roots), which
    // keeps them refused; until a refinement splits more they are not tried again (an attempt
    // walks the whole tree: 5–8 ms at 24 576 tetrahedra).
    if (levels) bisection_refused_at_splits_.reset();
    else bisection_refused_at_splits_ = hierarchy_->n_splits();
    return levels;
  }

  std::unique_ptr<Multigrid> grid_levels(const LevelSettings& settings, const SolverOptions& options,
                                         const std::string& prefix, Multigrid* earlier, bool rebuild_after_edits) {
    if (settings.max_levels > 2) throw std::invalid_argument(settings.flag + "pc_mg_levels: grid coarsening gives 2 levels");
    static const PetscLogEvent event = log_event("SnedeGridLevels");
    ScopedEvent logged(event);
    // Volume meshes keep the grid of the first build, so that levels follow edits. A membrane's
    // gets a grid chosen for each build: on the bell of the membrane-cut scene, levels on the first
    // build's grid made Newton's line search fail after a cut (DIVERGED_LINE_SEARCH after 218
    // iterations) where a grid chosen anew converged (its positive-part tangent is sensitive to
    // the coarse space; not understood yet).
    const bool keeps_grid = !model_.body().mesh().is_surface();
    if (earlier && keeps_grid && !rebuild_after_edits) {
      if (std::unique_ptr<Multigrid> edited = earlier->follow_edits()) {
        ++levels_edited_;
        return edited;
      }
    }
    auto grid = grid_geometry_ && keeps_grid
                    ? std::make_unique<GridMultigrid>(model_, *grid_geometry_)
                    : std::make_unique<GridMultigrid>(
                          model_, options.number_option(prefix + "mg_grid_width", GridMultigrid::default_grid_width));
    grid_geometry_ = grid->geometry();
    return grid;
  }

  // An option for another kind of levels than those made is a mistake the user should hear of,
  // except the grid's width on bisection levels chosen by "auto": grid levels take over after
  // the first cut or flip (checked now all the same).
  static void refuse_options_of_other_levels(const Multigrid& levels, const LevelSettings& settings,
                                             const SolverOptions& options, const std::string& prefix) {
    const std::string source = levels.source();
    const bool grid_may_follow = source == "bisection" && settings.coarsening == "auto";
    if (grid_may_follow)
      GridMultigrid::require_valid_width(
          options.number_option(prefix + "mg_grid_width", GridMultigrid::default_grid_width));
    for (const auto& [name, applies_to] : {std::pair<std::string, std::string>{"mg_aggregate_width", "aggregation"},
                                           {"mg_aggregation_smoothing", "aggregation"}, {"mg_grid_width", "grid"}})
      if (source != applies_to && !(applies_to == "grid" && grid_may_follow) && options.string_option(prefix + name))
        throw std::invalid_argument(settings.flag + name + " applies to " + applies_to + " levels; these are " +
                                    source + " levels (" + settings.flag + "mg_coarsening chooses)");
  }

  Model& model_;
  const RefinementHierarchy* hierarchy_;
  // "auto" found no bisection levels for the mesh when the hierarchy had recorded this many
  // bisections (bisection_levels).
  std::optional<std::size_t> bisection_refused_at_splits_;
  // The grid of the first grid levels: every later grid level lies on it (the edited ones must,
  // and the reference rebuild_after_edits makes the same levels from scratch).
  std::optional<GridGeometry> grid_geometry_;
  std::size_t levels_edited_ = 0;
};

class RankLevelSource final : public LevelSource {
 public:
  explicit RankLevelSource(DistributedStatic& problem) : problem_(problem) {}

  // rank_aggregation.hpp aggregates no membrane.
  bool has_levels() const override { return problem_.part().local->cell_dim() == problem_.dim(); }

  std::unique_ptr<Multigrid> make_levels(const SolverOptions& options, const std::string& prefix,
                                         Multigrid* /*earlier*/, bool /*rebuild_after_edits*/) override {
    const LevelSettings settings = read_settings(options, prefix);
    if (settings.coarsening != "auto" && settings.coarsening != "aggregation")
      throw std::invalid_argument(settings.flag + "mg_coarsening " + settings.coarsening +
                                  ": on MPI ranks 'mg' coarsens by aggregation of each rank's vertices (bisection "
                                  "and grid levels need the whole mesh)");
    if (options.string_option(prefix + "mg_grid_width"))
      throw std::invalid_argument(settings.flag + "mg_grid_width does not apply on MPI ranks, whose 'mg' levels are "
                                  "aggregates of each rank's vertices");
    // Smoothed by default on ranks, where no grid levels can stand in for plain aggregates: on
    // the 162 000-tetrahedron cube CG takes 28 iterations with plain aggregates, 18 smoothed,
    // 16 serially with grid levels (docs/results/mpi.md).
    return std::make_unique<RankAggregationMultigrid>(
        problem_, settings.max_levels, aggregate_width(options, prefix),
        options.bool_option(prefix + "mg_aggregation_smoothing", true));
  }

 private:
  DistributedStatic& problem_;
};

}  // namespace

std::unique_ptr<LevelSource> mesh_level_source(Model& model, const RefinementHierarchy* hierarchy) {
  return std::make_unique<MeshLevelSource>(model, hierarchy);
}

std::unique_ptr<LevelSource> rank_level_source(DistributedStatic& problem) {
  return std::make_unique<RankLevelSource>(problem);
}

}  // namespace snede
