// Static relaxation (§2.4, §3.1, §4.4.2) with PETSc: linear CG (KSPCG on the tangent
// shell), nonlinear CG (SNESNCG; Polak-Ribière or Fletcher-Reeves through
// -<prefix>snes_ncg_type, line searches cp, snede_newton, snede_secant) and truncated
// Newton (SNESNEWTONLS with an inner KSPCG on the shell and Eisenstat-Walker tolerances).
// Every object carries the options prefix and reads the solver's own options database
// (core/solver_options.hpp); SetFromOptions is called after snede's defaults, so the
// solver's options override the defaults and the command line overrides everything.
//
// It drives any Problem (problem.hpp) on its communicator (issue 36): the serial Model, whose
// mesh may be cut or refined between solves, or a DistributedStatic on N ranks — the same
// methods, criteria and preconditioners ("mg" by aggregation on ranks, rank_aggregation.hpp).
#pragma once

#include <petscksp.h>
#include <petscsnes.h>

#include <string>
#include <vector>

#include <memory>
#include <optional>

#include "core/solver_options.hpp"
#include "problem/model.hpp"
#include "problem/model_problem.hpp"
#include "multigrid/grid_multigrid.hpp"
#include "multigrid/multigrid.hpp"
#include "problem/piece_holding.hpp"
#include "solvers/preconditioner_reuse.hpp"
#include "problem/problem.hpp"
#include "problem/tangent_assembly.hpp"
#include "solvers/solve_result.hpp"
#include "solvers/static_options.hpp"
#include "problem/stopping.hpp"
#include "topology/refinement_hierarchy.hpp"

namespace snede {

class StaticSolver {
 public:
  // hierarchy: the mesh's bisection hierarchy, which "mg" coarsens along when it can (may be
  // null); it must outlive the solver.
  StaticSolver(Model& model, StaticOptions options, const RefinementHierarchy* hierarchy = nullptr);
  // Collective on problem.comm(); the problem must outlive the solver. Throws
  // std::invalid_argument (the same on every rank) for options that differ between the ranks.
  StaticSolver(Problem& problem, StaticOptions options);
  ~StaticSolver();
  StaticSolver(const StaticSolver&) = delete;
  StaticSolver& operator=(const StaticSolver&) = delete;

  // Relaxes the problem's state in place (starting from it, constraints enforced).
  SolveResult solve();
  KSP ksp() const;  // linear CG's KSP, or Newton's inner KSP
  SNES snes() const { return snes_; }
  const StaticOptions& options() const { return options_; }
  // The PC type in use, and the assembled matrix it is built from (null without one).
  const std::string& preconditioner() const { return pc_type_; }
  Mat preconditioner_matrix() const { return assembled_ ? assembled_->mat() : nullptr; }
  // Per multigrid level, coarsest first, the mesh last: elements (bisection levels), grid node
  // copies or aggregates (the mesh's cells last). Empty unless the PC is "mg".
  std::vector<std::size_t> multigrid_levels() const {
    return multigrid_ ? multigrid_->level_sizes() : std::vector<std::size_t>{};
  }
  // Unknowns per multigrid level, coarsest first; and what made the levels ("bisection",
  // "grid", "aggregation"; empty unless the PC is "mg").
  std::vector<std::size_t> multigrid_unknowns() const {
    return multigrid_ ? multigrid_->level_unknowns() : std::vector<std::size_t>{};
  }
  std::string multigrid_source() const { return multigrid_ ? multigrid_->source() : ""; }
  // The serial model solved (std::logic_error for a distributed problem).
  Model& model();
  Problem& problem() { return problem_; }
  // Seconds the last solve spent following mesh and constraint changes before iterating: new
  // vectors, the assembled tangent's sparsity, the multigrid levels (0 when nothing changed).
  double follow_seconds() const { return follow_seconds_; }
  // Times the preconditioner was filled (assembled tangent, multigrid levels at a state) since
  // the solver was made: reuse across Newton iterations and solves keeps it below their count.
  std::size_t preconditioner_fills() const { return preconditioner_fills_; }
  // Times multigrid levels were made (a grid, aggregates or a cut through the bisection tree,
  // with their interpolations) since the solver was made: after a mesh change, or a change of
  // constraints the levels could not take over in place.
  std::size_t multigrid_builds() const { return multigrid_builds_; }
  // How many of those were grid levels made from the earlier ones after an edit (on the grid of
  // the first build, only the node copies the edit reached found again: grid_multigrid.hpp).
  std::size_t multigrid_edits() const { return multigrid_edits_; }
  // Times the assembled tangent's sparsity was made since the solver was made: once per change
  // of the mesh's elements, not for vertices moved alone (a cut's snap).
  std::size_t sparsity_builds() const { return sparsity_builds_; }
  // How many of those were made from the earlier sparsity after an edit (only the touched
  // vertices' rows found again: tangent_assembly.hpp).
  std::size_t sparsity_edits() const { return sparsity_edits_; }
  // Times every element's matrix was assembled into the tangent since the solver was made. After a
  // cut or a refinement, Newton's kept Galerkin levels on a tangent that does not depend on the
  // state (a linear material) take one made from the earlier one instead, with only the blocks
  // the edit touched computed (tangent_assembly.hpp).
  std::size_t tangent_assemblies() const { return tangent_assemblies_; }
  // Times every piece of the mesh was labelled for the check that constraints hold each one
  // (piece_holding.hpp): once, then after edits only when a piece split off, pieces were joined
  // or a piece is loose (-static_rebuild_after_edits: after every change of the elements).
  std::size_t piece_labellings() const { return piece_holding_ ? piece_holding_->whole_labellings() : 0; }
  // The mesh's bisection hierarchy, once it has one (a mesh first refined after the solver was
  // made): the next levels, made after that refinement, coarsen along it.
  void use_hierarchy(const RefinementHierarchy* hierarchy) {
    if (hierarchy != hierarchy_) bisection_refused_at_splits_.reset();
    hierarchy_ = hierarchy;
  }

 private:
  // Solves `problem`, or the model problem `owned` when it is null.
  StaticSolver(std::unique_ptr<ModelProblem> owned, Problem* problem, StaticOptions options,
               const RefinementHierarchy* hierarchy);
  // Whether the multigrid levels are still those of the mesh (and of its constraints' projections).
  bool levels_match() const;
  bool levels_match_mesh() const;
  void create_objects();
  // After a mesh change: new vectors if the size changed (same solver objects, so a user's
  // handle and options survive), a new assembled tangent if its sparsity is out of date.
  void follow_mesh_changes();
  // Newton's inner tolerance (unless the options choose one): Eisenstat–Walker's forcing without
  // a PC, else a fixed relative tolerance, looser with Galerkin levels kept through the solve.
  void choose_forcing(bool preconditioned);
  static constexpr double set_up_levels_inner_rtol = 1e-3;
  static constexpr double kept_levels_inner_rtol = 1e-2;
  // After vertices moved alone: the kept levels and assembled tangent take the mesh over
  // unchanged (true), or nothing is kept (false).
  bool carry_levels_over_moved_vertices();
  // New vectors if `resized`, the sparsity kept or made anew, the multigrid levels made anew,
  // and the solver objects reset onto them.
  void make_structures_for_mesh(bool resized);
  // "auto" after the mesh grew or shrank past multigrid_from_cells: the other choice, with new
  // solver objects (the old ones left to any handle that holds them).
  void choose_preconditioner_again();
  // Leaves the KSP/SNES without callbacks into this solver, for handles that outlive it.
  void leave_solver_objects() noexcept;
  // The matrix the PC is built from: the shell, or an assembled tangent for the current mesh.
  Mat preconditioning_matrix();
  // PC "mg": the levels for the current mesh (bisection when the hierarchy gives them, else a
  // grid or aggregation), and whether the PC then needs the assembled tangent. Grid levels are
  // made from `earlier` (the levels of the mesh before an edit) when they can follow the edit.
  void build_multigrid(Multigrid* earlier = nullptr);
  // "mg" on a distributed problem: aggregation levels on each rank's vertices.
  void build_rank_multigrid(const std::string& coarsening, int max_levels);
  // The levels built anew and configured on `pc`.
  void set_up_multigrid(PC pc);
  // Configures `pc` as a PCMG over the current levels.
  void configure_multigrid(PC pc);
  // Newton's Jacobian callback: the assembled tangent (or the multigrid levels) are refilled
  // unless the SNES lags the preconditioner at this iteration (-<prefix>snes_lag_preconditioner).
  void refill_preconditioner(SNES snes, Vec x);
  // Whether the filled preconditioner is that of the current system (scale and projections).
  bool filled_for_current_system() const;
  // Whether Newton keeps Galerkin levels through a solve and across solves (solve_nonlinear).
  bool keeps_galerkin_levels() const;
  // Whether Galerkin levels keep their interpolation when only the constraints changed.
  bool lags_constraint_changes() const;
  // The levels take changed constraints over (follow_constraints), or are made anew for them.
  void take_over_constraints();
  // The assembled tangent and the multigrid levels at the state u (logged as SnedeTangentAssembly
  // and SnedeLevelsUpdate), and the fill remembered for reuse.
  void fill_preconditioner(Vec u);
  // A number from the option database (-<prefix>name), or `fallback`.
  double number_option(const std::string& name, double fallback) const;
  double current_tolerance() const;
  // Criterion "relative": ε‖r(u₀)‖ from the starting residual's norm.
  void anchor_relative_rule(double initial_norm);
  SolveResult solve_linear();
  SolveResult solve_nonlinear();
  void finish(SolveResult& result, double start_seconds, double start_flops);

  static PetscErrorCode residual_callback(SNES, Vec x, Vec F, void* context);
  static PetscErrorCode objective_callback(SNES, Vec x, PetscReal* value, void* context);
  static PetscErrorCode jacobian_callback(SNES, Vec x, Mat J, Mat P, void* context);
  // Newton's inner solve must give a descent direction; if it did not, the steepest descent.
  static PetscErrorCode descent_direction_callback(SNESLineSearch, Vec u, Vec step, PetscBool* changed,
                                                   void* context);
  static PetscErrorCode snes_converged_callback(SNES, PetscInt it, PetscReal xnorm, PetscReal snorm,
                                                PetscReal fnorm, SNESConvergedReason* reason, void* context);
  static PetscErrorCode ksp_converged_callback(KSP, PetscInt it, PetscReal rnorm, KSPConvergedReason* reason,
                                               void* context);

  std::unique_ptr<ModelProblem> owned_problem_;  // made for a Model
  Problem& problem_;
  Model* model_;  // the serial model, or null on a distributed problem (no edits, no hierarchy)
  StaticOptions options_;
  SolverOptions option_database_;  // read by the PETSc objects below
  KspHandle ksp_;    // linear CG only
  SnesHandle snes_;  // nonlinear methods only
  VecHandle residual_;
  std::string pc_type_;
  bool automatic_ = false;             // pc_type_ was chosen by "auto": chosen again as the mesh grows
  bool pc_needs_matrix_ = false;       // the PC type needs entries (not none, jacobi or mg)
  bool needs_matrix_ = false;          // the PC needs an assembled tangent (that, or Galerkin mg)
  std::unique_ptr<AssembledProblemTangent> assembled_;  // that tangent, for the current mesh
  MatrixFormat assembled_format_ = MatrixFormat::aij;
  MatrixFormat assembled_tangent_format() const;  // what the PC and the levels read
  const RefinementHierarchy* hierarchy_ = nullptr;
  // "auto" found no bisection levels for the mesh when the hierarchy had recorded this many
  // bisections. A cut, a flip or a collapse only takes elements out of the tree (into new roots),
  // which keeps them refused; until a refinement splits more they are not tried again (an attempt
  // walks the whole tree: 5–8 ms at 24 576 tetrahedra).
  std::optional<std::size_t> bisection_refused_at_splits_;
  std::unique_ptr<Multigrid> multigrid_;  // PC "mg": the levels for the current mesh
  std::vector<double> smoother_bounds_;  // mg: Chebyshev's estimates from an earlier set-up, reused
  // mg: remembers Chebyshev's estimates once the PC has made them (after a solve).
  void remember_smoother_bounds();
  bool preconditioner_filled_ = false;  // filled since it was made (for lagging)
  double filled_at_scale_ = 0;          // the system scale it was filled with
  std::uint64_t filled_for_constraints_ = 0;  // ... and the constraints' projection fingerprint
  std::size_t preconditioner_fills_ = 0;
  std::size_t multigrid_builds_ = 0;
  std::size_t multigrid_edits_ = 0;
  // The grid of the first grid levels: every later grid level lies on it (the edited ones must,
  // and the reference rebuild_after_edits makes the same levels from scratch).
  std::optional<GridGeometry> grid_geometry_;
  std::size_t sparsity_builds_ = 0;
  std::size_t sparsity_edits_ = 0;
  std::size_t tangent_assemblies_ = 0;
  // The assembled tangent was made from the earlier one after an edit, its values already filled:
  // the next fill does not assemble it again.
  bool tangent_follows_edits_ = false;
  double tangent_edited_at_scale_ = 0;  // ... in the system scale of then
  // After an edit of the mesh's elements: the tangent made from the earlier one (its sparsity;
  // its values too when the levels are kept across solves and the tangent does not depend on the
  // state); false if a new one must be made.
  bool tangent_follows_edits();
  bool keeps_levels_through_solve_ = false;  // Galerkin levels kept through a solve (solve_nonlinear)
  PreconditionerReuse reuse_;                // ... and through the next ones while they serve
  bool linear_solve_pending_ = false;        // a Newton iteration's CG with kept levels not yet recorded
  // Tells reuse_ the CG iterations of the last Newton iteration with kept levels, once; whether
  // that linear solve failed.
  bool record_last_linear_solve();
  // -<prefix>rebuild_after_edits: every structure made from scratch after each mesh change, the
  // reference the structures that follow the change are compared with (issue 49, item 7).
  bool rebuild_after_edits_;
  std::uint64_t generation_ = 0;
  StoppingRule rule_;  // the stopping rule of the current solve, scaled to the model
  double external_norm_ = 0;
  double system_scale_ = 1;  // CG and SNES see J, F and the energy divided by it (the force scale)
  double reaction_norm_ = 0;  // reactions used by the KSP test (at the start of a linear solve)
  std::vector<double> history_;
  double follow_seconds_ = 0;
  // Whether every piece of the body is held (checked before each solve; serial models).
  std::optional<PieceHolding> piece_holding_;
};

// Registers snede's line searches with PETSc (idempotent): snede_newton, snede_secant.
void register_line_searches();

}  // namespace snede
