// Multigrid for any mesh on a coarse background grid with virtual nodes. The coarse space is the
// piecewise linear functions of a Kuhn-triangulated grid laid over the reference configuration
// (non-nested: a fine vertex takes the barycentric weights of the grid simplex holding it), so,
// like the bisection levels and unlike rigid aggregates, it reproduces every linear field. A cut
// must not let one coarse function tie the two lips: each grid node gets one copy per connected
// piece of the fine vertices it interpolates to (joined by fine edges among them) — the virtual
// node algorithm (Molino, Bridson & Fedkiw 2004) and composite finite elements (Liehr et al.
// 2009), applied to the coarse space only. Columns are projected by the constraints and
// orthonormalised per node copy (dropping what the constraints forbid). Coarse operators are
// Galerkin products with the assembled tangent, as for aggregation.
#pragma once

#include <cstdint>
#include <vector>

#include "core/petsc_handle.hpp"
#include "solve/multigrid.hpp"

namespace snede {

class GridMultigrid final : public GalerkinMultigrid {
 public:
  // Two levels: `fine`'s mesh (volume or membrane) and a grid `grid_width` vertex spacings wide
  // (coarse_basis.hpp: the edge of a cube per fine vertex).
  // Throws std::invalid_argument for a non-positive width.
  explicit GridMultigrid(Model& fine, double grid_width = default_grid_width);
  // 4 spacings is 3 mean edge lengths on a uniform mesh, the fastest of 2, 3 and 4 in
  // studies/benchmarks/interactive_cut.py on the block and the liver; on a mesh refined along a needle's
  // shaft, 3 mean edge lengths made a coarse level larger than the fine one (needle3d_rates.py).
  static constexpr double default_grid_width = 4.0;
  // Throws std::invalid_argument naming mg_grid_width unless `grid_width` is finite and ≥ 1.
  static void require_valid_width(double grid_width);

  const char* source() const override { return "grid"; }
  int n_levels() const override { return 2; }
  // Coarse node copies, then the fine mesh's cells.
  std::vector<std::size_t> level_sizes() const override;
  std::vector<std::size_t> level_unknowns() const override;
  void configure(PC pc, const SolverOptions& options, const std::vector<double>& smoother_bounds = {}) override;
  // Block storage: the Galerkin product reads the vertex blocks, and the smoother's products
  // with the fine matrix are faster on it than on AIJ (0.45 against 0.99 ms at 98k tetrahedra).
  MatrixFormat assembled_tangent_format() const override { return MatrixFormat::baij; }

 protected:
  // By vertex blocks (galerkin_product.hpp): the fine matrix is the assembled tangent, in BAIJ.
  std::unique_ptr<CoarseProduct> galerkin_product(Mat finer, PetscInt level) const override;

 private:
  std::size_t n_nodes_ = 0;
  PetscInt n_unknowns_ = 0;
  MatHandle interpolation_;
  BlockInterpolation blocks_;  // the same, vertex by vertex
};

}  // namespace snede
