// Multigrid for any mesh, by aggregation (smoothed-aggregation AMG's tentative prolongator,
// Vaněk, Mandel & Brezina 1996, with geometric aggregates): the thesis's meshes change under
// cuts, flips and needles (§3.2, §6.5, §7.3) and organ meshes come without a bisection history,
// so the coarse levels cannot be coarser meshes. Instead each coarse unknown is a rigid motion
// of an aggregate: a set of nodes that lie in one cell of a grid over the reference
// configuration *and* are connected by the mesh's edges inside it. A cut that separates an
// aggregate's nodes splits it in one per connected piece (the virtual node idea of Molino et al.
// 2004), so the coarse space never couples the two lips, and a piece cut free never moves with
// the rest. Coarser levels aggregate the aggregates on a grid twice as coarse.
//
// Each aggregate's rigid modes, projected by the constraints of its vertices (so that a coarse
// correction never moves a support), are orthonormalised (QR); the orthonormal columns are the
// interpolation's columns, the triangular factor the aggregate's rigid modes on the next level.
// PCMG forms the coarse operators as Galerkin products with the assembled fine tangent
// (symbolically once per mesh, numerically whenever the tangent is refilled), smooths with
// Chebyshev/Jacobi and factors the coarsest level. Building the levels costs O(n) and needs
// neither the state nor the material: after a cut it is the only thing rebuilt.
#pragma once

#include <cstdint>
#include <vector>

#include "core/petsc_handle.hpp"
#include "multigrid/multigrid.hpp"

namespace snede {

class AggregationMultigrid final : public GalerkinMultigrid {
 public:
  // Levels for `fine`'s mesh (volume meshes: triangles in 2D, tetrahedra in 3D): coarsened
  // until the coarsest level has few enough unknowns for a direct solve, or to `max_levels`
  // counting the fine one (0: no limit). Throws std::invalid_argument for max_levels 1 or
  // negative, or more levels than the mesh can give, and for a surface mesh.
  // smooth_first_level: every level's interpolation is smoothed (smoothed_aggregation.hpp).
  // aggregate_width: the first level's grid cells, in mean edge lengths.
  explicit AggregationMultigrid(Model& fine, int max_levels = 0, bool smooth_first_level = false,
                                double aggregate_width = default_aggregate_width);
  // On a structured tetrahedral mesh about 3 vertices per direction (studies/benchmarks/interactive_cut.py
  // measured widths 2 to 4; see docs/results/interactive.md).
  static constexpr double default_aggregate_width = 2.5;
  ~AggregationMultigrid() override;

  const char* source() const override { return "aggregation"; }
  int n_levels() const override { return static_cast<int>(coarse_.size()) + 1; }
  // Aggregates per coarse level, coarsest first, then the fine mesh's cells.
  std::vector<std::size_t> level_sizes() const override;
  std::vector<std::size_t> level_unknowns() const override;
  void configure(PC pc, const SolverOptions& options, const std::vector<double>& smoother_bounds = {}) override;

 private:
  struct Level {
    std::size_t n_aggregates = 0;
    PetscInt n_unknowns = 0;
    MatHandle interpolation;  // from this level to the next finer one
  };

  std::vector<Level> coarse_;  // coarsest first
};

}  // namespace snede
