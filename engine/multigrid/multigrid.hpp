// What the static solver needs from a multigrid hierarchy, whatever made it: the bisection
// tree (bisection_multigrid.hpp: coarse meshes, matrix-free levels), a background grid with
// virtual nodes (grid_multigrid.hpp) or aggregation (aggregation_multigrid.hpp), both of any
// mesh, with Galerkin levels from an assembled tangent.
#pragma once

#include <petscksp.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/petsc_handle.hpp"
#include "core/solver_options.hpp"
#include "multigrid/galerkin_product.hpp"
#include "problem/model.hpp"
#include "problem/tangent_assembly.hpp"

namespace snede {

class Multigrid {
 public:
  virtual ~Multigrid() = default;
  // "bisection", "grid" or "aggregation".
  virtual const char* source() const = 0;
  // Whether the fine mesh and its constraints' projections are still those the levels were
  // made for (no edit, no vertex fixed, released or made to slide since).
  virtual bool matches() const = 0;
  // Whether only the mesh is still the same (the constraints may have changed).
  virtual bool matches_mesh() const = 0;
  // After the fine constraints changed (not the mesh): the levels take them over. False if
  // they cannot (then the levels must be made anew).
  virtual bool follow_constraints() = 0;
  // After vertices moved in the reference configuration and no element changed (a cut's snap):
  // levels that still precondition the mesh take it over and return true, keeping what they
  // were made with (interpolation, products) for the earlier positions until they are made
  // anew; false if they must be made anew now.
  virtual bool carry_over_moved_vertices() { return false; }
  // After edits of elements: levels for the mesh as it is now made from these, equal to levels
  // made anew, or null where they are made anew only (the default).
  virtual std::unique_ptr<Multigrid> follow_edits() { return nullptr; }
  // Whether the levels were carried over moved vertices since they were made.
  virtual bool made_for_earlier_positions() const { return false; }
  // Levels including the finest.
  virtual int n_levels() const = 0;
  // Per level, coarsest first, the fine mesh last: elements (bisection levels) or nodes
  // (aggregates; the fine level's cells last).
  virtual std::vector<std::size_t> level_sizes() const = 0;
  // Unknowns per level, coarsest first, the fine level last.
  virtual std::vector<std::size_t> level_unknowns() const = 0;
  // Whether the PC's preconditioning matrix must be the assembled fine tangent (Galerkin
  // levels are products with it) rather than the shell.
  virtual bool needs_assembled_tangent() const = 0;
  // The format that assembled tangent must have: what the levels' Galerkin products read.
  virtual MatrixFormat assembled_tangent_format() const { return MatrixFormat::aij; }
  // Makes `pc` a PCMG over these levels. `smoother_bounds`: Chebyshev's largest eigenvalue per
  // smoothed level (finest last) from an earlier set-up with as many levels; empty: estimate.
  virtual void configure(PC pc, const SolverOptions& options, const std::vector<double>& smoother_bounds) = 0;
  // Relinearises the levels at the fine state u, after `assembled_tangent` (null for levels
  // that do not need it) was filled at u: matrix-free levels take the state, Galerkin levels
  // recompute their products with the matrix.
  virtual void update(Vec u, Mat assembled_tangent) = 0;
  // The preconditioner was found indefinite (CG met negative curvature in it). Levels that can
  // make their operators positive definite switch to that from the next update() on and return
  // true; false if nothing would change.
  virtual bool prefer_positive_definite() { return false; }
};

// Levels of any mesh (grid_multigrid.hpp, aggregation_multigrid.hpp) whose coarse operators are
// Galerkin products with the assembled fine tangent. Their interpolation holds the mesh and the
// constraints' projections, so any change of either means new levels.
class GalerkinMultigrid : public Multigrid {
 public:
  bool matches() const override;
  bool matches_mesh() const override;
  bool follow_constraints() override { return false; }
  // An interpolation for the earlier positions is still an interpolation of the same vertices,
  // and the products of the earlier tangent still an SPD preconditioner of the present one.
  bool carry_over_moved_vertices() override;
  bool made_for_earlier_positions() const override { return carried_; }
  bool needs_assembled_tangent() const override { return true; }
  // Recomputes Pᵀ A P level by level from the refilled fine matrix (numeric only while the
  // matrices are those of the first call: the mesh has not changed).
  void update(Vec u, Mat assembled_tangent) override;

 protected:
  explicit GalerkinMultigrid(Model& fine);
  // Makes `pc` a PCMG over `interpolations` (each level to the next finer one, coarsest first,
  // owned by the subclass): Chebyshev/Jacobi smoothers that estimate their bounds (the levels of
  // a changing mesh are rebuilt after every edit, and a cut's slivers change the spectrum), LU
  // on the coarsest level, and coarse operators from update().
  void configure_levels(PC pc, std::vector<Mat> interpolations, const SolverOptions& options);
  // The Galerkin product of `finer` with the interpolation into it from `level` (0: the
  // coarsest): PETSc's, unless the levels know their interpolation in vertex blocks.
  virtual std::unique_ptr<CoarseProduct> galerkin_product(Mat finer, PetscInt level) const;
  Model& fine_;

 private:
  std::uint64_t revision_;
  std::uint64_t topology_revision_;
  bool carried_ = false;  // carried over moved vertices (carry_over_moved_vertices)
  std::uint64_t constraints_;
  PC pc_ = nullptr;                      // the PCMG of the last configure_levels (owned by its KSP)
  std::vector<Mat> interpolations_;      // coarsest first
  Mat fine_matrix_ = nullptr;            // the fine matrix the products were made with
  std::vector<std::unique_ptr<CoarseProduct>> coarse_;  // Pᵀ A P per coarse level, finest coarse level first
};

// Chebyshev/Jacobi on one smoothed level: with `largest_bound` > 0 the bounds are fixed from
// it (an earlier estimate, with a safety factor), else Chebyshev estimates them. With
// `point_blocks`, Jacobi inverts the level matrix's diagonal blocks (PCPBJACOBI: an assembled
// matrix with the block size of a vertex) rather than its diagonal.
void set_chebyshev_jacobi_smoother(KSP smoother, const SolverOptions& options, double largest_bound,
                                   bool point_blocks = false);
// The largest eigenvalues Chebyshev estimated on the smoothed levels of a PCMG (finest last);
// empty if a level did not estimate (fixed bounds, another smoother).
std::vector<double> chebyshev_estimates(PC pc);
// The coarsest level's solve: a direct factorisation of its assembled matrix (on every rank,
// of the whole level, when the PC is on several ranks).
void set_direct_coarse_solve(PC pc, const SolverOptions& options);

}  // namespace snede
