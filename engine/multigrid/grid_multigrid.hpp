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
//
// After edits the levels are made from the earlier ones (follow_edits, issue 49): on the same
// grid, only the grid nodes an edited vertex uses (or used) get their copies found again, from
// the elements around them; the others keep theirs.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/petsc_handle.hpp"
#include "mesh/edit_footprint.hpp"
#include "multigrid/multigrid.hpp"

namespace snede {

class DisjointSets;

// Where a grid lies: cubes (squares) of side `width` from `low` over the box up to `high`.
struct GridGeometry {
  int dim = 3;
  std::array<double, 3> low{}, high{};
  double width = 0;
};

class GridMultigrid final : public GalerkinMultigrid {
 public:
  // Two levels: `fine`'s mesh (volume or membrane) and a grid `grid_width` vertex spacings wide
  // (coarse_basis.hpp: the edge of a cube per fine vertex) over its bounding box.
  // Throws std::invalid_argument for a non-positive width.
  explicit GridMultigrid(Model& fine, double grid_width = default_grid_width);
  // The same on a given grid (one kept from an earlier mesh).
  GridMultigrid(Model& fine, const GridGeometry& geometry);
  // The grid `grid_width` vertex spacings wide over `mesh`'s bounding box.
  static GridGeometry geometry_for(const Mesh& mesh, double grid_width);
  const GridGeometry& geometry() const { return geometry_; }
  // The levels of the mesh as it is now, on the same grid, made from these: equal to levels
  // made anew on that grid (coarse numbering included). Null if a vertex left the id range.
  std::unique_ptr<Multigrid> follow_edits() override;
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
  // The edit of follow_edits.
  GridMultigrid(Model& fine, const GridMultigrid& earlier);
  // Locates vertex v (its weights on its grid simplex; none for a removed vertex).
  void locate(VertexId v);
  // Joins, in `copies`, the (vertex, slot) pairs on one grid node that a fine edge links, for the
  // edges of every element with a corner `marked` (null: every element).
  void join_linked_pairs(DisjointSets& copies, const std::vector<bool>* marked) const;
  // The copies, columns, blocks and P from each used pair's copy label (-1: the pair is unused):
  // copies are numbered in the order of their first pair, as a whole build numbers them.
  void make_levels(const std::vector<std::int32_t>& label);

  GridGeometry geometry_;
  std::unique_ptr<EditFootprint> edits_;  // since these levels were made
  std::vector<std::int64_t> pair_node_;   // per (vertex, slot): the grid node it uses, -1 if none
  std::vector<double> pair_weight_;       // its weight
  std::vector<std::int32_t> pair_copy_;   // its node copy, -1 if none
  std::vector<std::int64_t> copy_node_;   // per copy: its grid node
  std::size_t n_nodes_ = 0;
  PetscInt n_unknowns_ = 0;
  MatHandle interpolation_;
  BlockInterpolation blocks_;  // the same, vertex by vertex
};

}  // namespace snede
