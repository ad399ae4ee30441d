// Geometric multigrid on the bisection hierarchy (§6.5; §6.9 proposes it), matrix-free on every
// level. A coarse level is a cut through the refinement tree — every live element replaced by
// its ancestor at depth k — which for a compatibly labelled bisection is again a conforming
// mesh (checked here: same volume and boundary measure as the fine mesh). Each level gets its
// own ElasticBody and Model on that mesh, so its operator is the same tangent shell over the
// same element kernels, linearised at the fine state injected into its vertices (which are
// fine vertices). Interpolation follows the tree: a bisection midpoint takes the mean of its
// edge's ends, recursively down to the coarse vertices; it is projected by the constraints on
// both sides (P_fine · I · P_coarse), so a coarse correction never moves a support.
//
// PETSc's PCMG runs the cycle: Chebyshev/Jacobi smoothing on the shells (the diagonal comes
// from the element kernels), LU on the coarsest level's assembled tangent. The levels are
// chosen so that each halves h (about 2^dim times fewer elements) and holds the body (its
// constraints stop the rigid motions); a cut or a flip that takes elements out of the tree
// makes the coarser cuts non-conforming, and coarsening stops there.
#pragma once

#include <petscksp.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "core/petsc_handle.hpp"
#include "multigrid/multigrid.hpp"
#include "problem/tangent_assembly.hpp"
#include "topology/refinement_hierarchy.hpp"

namespace snede {

class BisectionMultigrid final : public Multigrid {
 public:
  // Builds the coarse levels of `fine`'s mesh from `hierarchy` (which must watch that mesh):
  // all it allows, or the finest `max_levels` (counting the fine one; 0: no limit).
  // Throws std::invalid_argument when not even one coarser level exists (a mesh never
  // refined, or one whose coarser cuts are not conforming), naming what is missing, or when
  // max_levels is 1 or more than there are.
  BisectionMultigrid(Model& fine, const RefinementHierarchy& hierarchy, int max_levels = 0);
  ~BisectionMultigrid();
  BisectionMultigrid(const BisectionMultigrid&) = delete;
  BisectionMultigrid& operator=(const BisectionMultigrid&) = delete;

  const char* source() const override { return "bisection"; }
  bool matches() const override;
  bool matches_mesh() const override;
  int n_levels() const override { return static_cast<int>(coarse_.size()) + 1; }
  // Elements per level, coarsest first, the fine mesh last.
  std::vector<std::size_t> level_sizes() const override;
  std::vector<std::size_t> level_unknowns() const override;
  bool needs_assembled_tangent() const override { return false; }
  // The coarse levels take the new constraints over and the interpolations are rebuilt,
  // without rebuilding the levels' meshes; false if a level is no longer held.
  bool follow_constraints() override;
  // PCMG over these levels: interpolations, the levels' own shells, Chebyshev/Jacobi
  // smoothers, LU on the coarsest level's assembled tangent. Call before PCSetFromOptions,
  // which may override them (-<prefix>mg_levels_ksp_type, -<prefix>mg_coarse_pc_type, ...).
  void configure(PC pc, const SolverOptions& options, const std::vector<double>& smoother_bounds = {}) override;
  // Linearises every coarse level at u (the fine state, injected) with the fine model's
  // operator scale, and refills the coarsest level's matrix.
  void update(Vec u, Mat assembled_tangent) override;
  // From then on the coarse levels are linearised at rest, where every material's tangent is
  // positive definite, instead of at the injected fine state: under large deformation a coarse
  // element can see a state whose tangent is indefinite while the fine tangent is not (a
  // 960-tetrahedron neo-Hookean beam, ν = 0.49, sagging a quarter of its length: Newton stopped
  // with DIVERGED_LINE_SEARCH; at rest it converged in 12 iterations). Not the default: on the
  // 98 304-tetrahedron block the injected state takes 56 CG iterations where rest takes 131.
  bool prefer_positive_definite() override;

 private:
  struct Level;
  // The coarse level that is a cut of the tree at depth `depth`; null if that cut is not a
  // conforming mesh of the same body.
  std::unique_ptr<Level> make_level(int depth, const std::vector<int>& node_depth) const;
  // The fine constraints of the level's vertices; whether they hold the level's body.
  bool copy_constraints(Level& level) const;
  // Interpolation from `coarse` to the level with vertex list `fine_vertices` (fine-mesh ids;
  // empty: the fine mesh itself, every vertex id).
  void make_interpolation(Level& coarse, const std::vector<VertexId>& fine_vertices) const;

  Model& fine_;
  const RefinementHierarchy& hierarchy_;
  std::uint64_t revision_;
  std::uint64_t constraints_;  // the fine constraints' projection fingerprint
  std::vector<std::pair<VertexId, VertexId>> midpoint_of_;  // per fine vertex: its bisected edge
  std::vector<std::unique_ptr<Level>> coarse_;               // coarsest first
  std::unique_ptr<AssembledTangent> coarsest_matrix_;
  bool coarse_at_rest_ = false;
};

}  // namespace snede
