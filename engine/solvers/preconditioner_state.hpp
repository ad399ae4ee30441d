// The preconditioner of a static solve and everything that decides when it is made, filled and
// kept (§3.1's CG, §2.4.3's truncated Newton): the PC type ("auto" chooses none or multigrid
// by the problem's size), the assembled tangent it reads, the multigrid levels the problem's
// level source makes (level_source.hpp), whether what was filled is that of the current system
// (scale, constraints), and Newton's reuse of Galerkin levels within and across solves
// (preconditioner_reuse.hpp). After a change of the mesh or the constraints it follows the
// change with as little made anew as it can: levels that take new constraints over, levels and
// tangent carried over moved vertices, a sparsity made from the earlier one. The static solver
// owns the PETSc objects; this class configures their PC.
#pragma once

#include <petscksp.h>
#include <petscsnes.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/solver_options.hpp"
#include "multigrid/level_source.hpp"
#include "multigrid/multigrid.hpp"
#include "problem/problem.hpp"
#include "solvers/preconditioner_reuse.hpp"
#include "solvers/static_options.hpp"

namespace snede {

class PreconditionerState {
 public:
  // The PC type from -<prefix>pc_type or options.preconditioner ("auto" when empty); `levels`
  // may be null (then "mg" has none). std::invalid_argument for a PC the method or the ranks
  // cannot take. `problem`, `database` and `options` must outlive this object.
  PreconditionerState(Problem& problem, std::unique_ptr<LevelSource> levels, SolverOptions& database,
                      const StaticOptions& options);

  const std::string& type() const { return type_; }
  // "auto" chose the type and would now choose another (the mesh grew or shrank past
  // options.multigrid_from_cells).
  bool wants_other_type() const;
  // Chooses again; the levels for the new type are made first, so that an option they refuse
  // leaves everything as it was. The solver's PETSc objects must then be made anew.
  void choose_type_again();
  // Makes the levels if "mg" has none yet.
  void make_missing_levels();
  // The matrix the PC is built from: the problem's shell, or an assembled tangent of the mesh.
  Mat matrix();
  // Sets `pc`'s type and levels (a fresh PC, or one whose KSP was just made).
  void configure(PC pc);
  // After the solver's objects were reset for a new mesh: a fresh PC implementation of the type
  // (a reset PCGAMG keeps its levels' sizes), configured again.
  void configure_after_reset(PC pc);

  // What the problem's changes since the last solve need. Returns true when new structures were
  // made (new levels, a new or edited tangent): the solver's objects must be reset onto them
  // (then configure_after_reset). `resized`: the number of unknowns changed.
  bool follow_changes(bool resized, double scale, PC pc);
  // New structures for the mesh of now (a new or edited tangent, new or edited levels).
  void make_structures(double scale);

  // Whether what was filled is the preconditioner of the system in `scale` and of the
  // constraints of now.
  bool filled_for(double scale) const;
  // Assembles the tangent at u and updates the levels (SnedeTangentAssembly, SnedeLevelsUpdate).
  void fill(Vec u, double scale);

  // Newton: whether its Galerkin levels are kept through a solve and across solves.
  bool keeps_galerkin_levels() const;
  // At the start of a Newton solve: whether this solve keeps its levels (then call
  // lag_for_solve). Levels carried over moved vertices past their age need new structures
  // first (structures_outlived).
  bool begin_newton_solve();
  bool structures_outlived() const;
  // SNES's -snes_lag_preconditioner for the solve: -1 keeps what was filled, -2 fills once.
  PetscInt lag_for_solve(double scale, PC pc);
  // Newton's Jacobian callback: refills unless the SNES lags the preconditioner now.
  void refill_for_newton(SNES snes, Vec x, double scale, KSP ksp);
  // After an SNESSolve: the last Newton iteration's CG counts towards the levels' age, once;
  // whether that linear solve failed.
  bool record_last_linear_solve(KSP ksp);
  // After a whole solve (counts only for a Newton solve that kept its levels).
  void end_newton_solve(bool converged);
  // "mg": keeps Chebyshev's estimates of a converged solve's set-up for the next levels.
  void remember_smoother_bounds(PC pc);

  bool has_levels() const { return multigrid_ != nullptr; }
  Multigrid* multigrid() const { return multigrid_.get(); }
  bool needs_matrix() const { return needs_matrix_; }
  Mat assembled_matrix() const { return assembled_ ? assembled_->mat() : nullptr; }
  void use_hierarchy(const RefinementHierarchy* hierarchy) {
    if (level_source_) level_source_->use_hierarchy(hierarchy);
  }

  // Counters (static_solver.hpp documents them).
  std::size_t fills() const { return fills_; }
  std::size_t multigrid_builds() const { return multigrid_builds_; }
  std::size_t multigrid_edits() const { return level_source_ ? level_source_->levels_edited() : 0; }
  std::size_t sparsity_builds() const { return sparsity_builds_; }
  std::size_t sparsity_edits() const { return sparsity_edits_; }
  std::size_t tangent_assemblies() const { return tangent_assemblies_; }
  bool rebuild_after_edits() const { return rebuild_after_edits_; }

 private:
  std::string automatic_type() const;
  void make_levels(Multigrid* earlier = nullptr);
  void configure_levels(PC pc);
  MatrixFormat assembled_tangent_format() const;
  // The levels take changed constraints over, or are made anew for them, on a fresh PC.
  void take_over_constraints(PC pc);
  bool lags_constraint_changes() const;
  // After vertices moved alone: the kept levels and tangent take the mesh over unchanged.
  bool carry_over_moved_vertices();
  // After an edit of the elements: the tangent made from the earlier one (tangent_assembly.hpp).
  bool tangent_follows_edits(double scale);

  Problem& problem_;
  std::unique_ptr<LevelSource> level_source_;
  SolverOptions& database_;
  const StaticOptions& options_;
  std::string type_;
  bool automatic_ = false;        // type_ was chosen by "auto": chosen again as the mesh grows
  bool pc_needs_matrix_ = false;  // the PC type needs entries (not none, jacobi or mg)
  bool needs_matrix_ = false;     // the PC needs an assembled tangent (that, or Galerkin levels)
  std::unique_ptr<AssembledProblemTangent> assembled_;
  MatrixFormat assembled_format_ = MatrixFormat::aij;
  std::unique_ptr<Multigrid> multigrid_;
  std::vector<double> smoother_bounds_;  // Chebyshev's estimates from an earlier set-up, reused
  bool filled_ = false;                  // filled since it was made (for lagging)
  double filled_at_scale_ = 0;
  std::uint64_t filled_for_constraints_ = 0;  // the constraints' projection fingerprint then
  // The assembled tangent was made from the earlier one after an edit, its values already filled
  // in the system scale of then: the next fill does not assemble it again.
  bool tangent_follows_edits_ = false;
  double tangent_edited_at_scale_ = 0;
  bool keeps_levels_through_solve_ = false;  // Galerkin levels kept through a Newton solve
  PreconditionerReuse reuse_;                // ... and through the next ones while they serve
  bool linear_solve_pending_ = false;        // a Newton iteration's CG not yet recorded in reuse_
  // -<prefix>rebuild_after_edits: every structure made from scratch after each mesh change, the
  // reference the structures that follow the change are compared with (issue 49, item 7).
  bool rebuild_after_edits_;
  std::size_t fills_ = 0;
  std::size_t multigrid_builds_ = 0;
  std::size_t sparsity_builds_ = 0;
  std::size_t sparsity_edits_ = 0;
  std::size_t tangent_assemblies_ = 0;
};

// The tangent shell applies J/scale while a solve runs on the scaled system.
class ScaledOperator {
 public:
  ScaledOperator(Problem& problem, double scale) : problem_(problem) { problem_.set_operator_scale(1.0 / scale); }
  ~ScaledOperator() { problem_.set_operator_scale(1.0); }
  ScaledOperator(const ScaledOperator&) = delete;
  ScaledOperator& operator=(const ScaledOperator&) = delete;

 private:
  Problem& problem_;
};

}  // namespace snede
