// The preconditioner "mg" of a static solve on MPI ranks (issue 36): PCMG over the aggregation
// levels of rank_aggregation.hpp (each rank aggregates the vertices it owns), with coarse
// operators Pᵀ A P formed by PETSc from the assembled MPIAIJ tangent at each set-up,
// Chebyshev/Jacobi smoothing, and a direct solve of the coarsest level on every rank
// (PCREDUNDANT: it is small). The serial kinds of levels — coarser bisection meshes, a
// background grid with virtual nodes — need the whole mesh on one process.
#pragma once

#include "problem/distributed_static.hpp"
#include "multigrid/multigrid.hpp"
#include "multigrid/rank_aggregation.hpp"

namespace snede {

class RankAggregationMultigrid final : public Multigrid {
 public:
  // Collective. max_levels counts the fine level (0: coarsened until the coarsest level is
  // small); aggregate_width in mean edge lengths, as serially; smooth_first_level as
  // rank_aggregation_levels takes it.
  RankAggregationMultigrid(DistributedStatic& problem, int max_levels, double aggregate_width,
                           bool smooth_first_level);

  const char* source() const override { return "aggregation"; }
  // A distributed problem's mesh and constraints do not change.
  bool matches() const override { return true; }
  bool matches_mesh() const override { return true; }
  bool follow_constraints() override { return true; }
  int n_levels() const override { return static_cast<int>(levels_.global_unknowns.size()); }
  // Unknowns per coarse level, then the mesh's cells (all ranks'), coarsest first.
  std::vector<std::size_t> level_sizes() const override;
  std::vector<std::size_t> level_unknowns() const override;
  bool needs_assembled_tangent() const override { return true; }
  void configure(PC pc, const SolverOptions& options, const std::vector<double>& smoother_bounds) override;
  // PCMG forms the Galerkin products itself when it is set up with a refilled matrix.
  void update(Vec, Mat) override {}

 private:
  std::int64_t n_cells_;
  RankAggregationLevels levels_;
};

}  // namespace snede
