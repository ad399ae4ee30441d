#include "multigrid/rank_aggregation_multigrid.hpp"

#include "core/error.hpp"

namespace snede {

RankAggregationMultigrid::RankAggregationMultigrid(DistributedStatic& problem, int max_levels, double aggregate_width,
                                                   bool smooth_first_level)
    : n_cells_(problem.n_global_cells()),
      levels_(rank_aggregation_levels(problem.part(), problem.local_constraints(), aggregate_width, max_levels,
                                      default_direct_unknowns, smooth_first_level)) {}

std::vector<std::size_t> RankAggregationMultigrid::level_sizes() const {
  std::vector<std::size_t> sizes = level_unknowns();
  sizes.back() = static_cast<std::size_t>(n_cells_);
  return sizes;
}

std::vector<std::size_t> RankAggregationMultigrid::level_unknowns() const {
  return {levels_.global_unknowns.begin(), levels_.global_unknowns.end()};
}

void RankAggregationMultigrid::configure(PC pc, const SolverOptions& options, const std::vector<double>&) {
  const auto n = static_cast<PetscInt>(n_levels());
  SNEDE_PETSC(PCSetType(pc, PCMG));
  SNEDE_PETSC(PCMGSetLevels(pc, n, nullptr));
  SNEDE_PETSC(PCMGSetType(pc, PC_MG_MULTIPLICATIVE));
  SNEDE_PETSC(PCMGSetGalerkin(pc, PC_MG_GALERKIN_BOTH));
  for (PetscInt l = 1; l < n; ++l) {
    SNEDE_PETSC(PCMGSetInterpolation(pc, l, levels_.interpolations[static_cast<std::size_t>(l - 1)]));
    KSP smoother = nullptr;
    SNEDE_PETSC(PCMGGetSmoother(pc, l, &smoother));
    // The assembled fine tangent has vertex blocks (distributed_assembly.hpp): Jacobi by blocks
    // there, as on the serial Galerkin levels.
    set_chebyshev_jacobi_smoother(smoother, options, 0.0, l == n - 1);
  }
  set_direct_coarse_solve(pc, options);
}

}  // namespace snede
