// Static relaxation (§2.4, §3.1, §4.4.2) with PETSc: linear CG (KSPCG on the tangent
// shell), nonlinear CG (SNESNCG; Polak-Ribière or Fletcher-Reeves through
// -<prefix>snes_ncg_type, line searches cp, snede_newton, snede_secant) and truncated
// Newton (SNESNEWTONLS with an inner KSPCG on the shell and Eisenstat-Walker tolerances).
// Every object carries the options prefix and reads the solver's own options database
// (core/solver_options.hpp); SetFromOptions is called after snede's defaults, so the
// solver's options override the defaults and the command line overrides everything.
//
// It drives a Problem (problem.hpp) on its communicator (issue 36): the serial Model, whose
// mesh may be cut or refined between solves, or a DistributedStatic on N ranks — the same
// methods, criteria and preconditioners ("mg" by aggregation on ranks, rank_aggregation.hpp).
// The solver drives: it owns the PETSc objects, the solve loops and the stopping criterion;
// PreconditionerState (preconditioner_state.hpp) decides what the PC is made of and when.
#pragma once

#include <petscksp.h>
#include <petscsnes.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/solver_options.hpp"
#include "problem/distributed_static.hpp"
#include "problem/model.hpp"
#include "problem/model_problem.hpp"
#include "problem/piece_holding.hpp"
#include "problem/problem.hpp"
#include "problem/stopping.hpp"
#include "solvers/convergence_test.hpp"
#include "solvers/preconditioner_state.hpp"
#include "solvers/solve_result.hpp"
#include "solvers/static_options.hpp"
#include "topology/refinement_hierarchy.hpp"

namespace snede {

class StaticSolver {
 public:
  // hierarchy: the mesh's bisection hierarchy, which "mg" coarsens along when it can (may be
  // null); it must outlive the solver.
  StaticSolver(Model& model, StaticOptions options, const RefinementHierarchy* hierarchy = nullptr);
  // Collective on problem.comm(); the problem must outlive the solver. Throws
  // std::invalid_argument (the same on every rank) for options that differ between the ranks.
  StaticSolver(DistributedStatic& problem, StaticOptions options);
  ~StaticSolver();
  StaticSolver(const StaticSolver&) = delete;
  StaticSolver& operator=(const StaticSolver&) = delete;

  // Relaxes the problem's state in place (starting from it, constraints enforced).
  SolveResult solve();
  KSP ksp() const;  // linear CG's KSP, or Newton's inner KSP
  SNES snes() const { return snes_; }
  const StaticOptions& options() const { return options_; }
  // The PC type in use, and the assembled matrix it is built from (null without one).
  const std::string& preconditioner() const { return preconditioner_.type(); }
  Mat preconditioner_matrix() const { return preconditioner_.assembled_matrix(); }
  // Per multigrid level, coarsest first, the mesh last: elements (bisection levels), grid node
  // copies or aggregates (the mesh's cells last). Empty unless the PC is "mg".
  std::vector<std::size_t> multigrid_levels() const {
    return levels() ? levels()->level_sizes() : std::vector<std::size_t>{};
  }
  // Unknowns per multigrid level, coarsest first; and what made the levels ("bisection",
  // "grid", "aggregation"; empty unless the PC is "mg").
  std::vector<std::size_t> multigrid_unknowns() const {
    return levels() ? levels()->level_unknowns() : std::vector<std::size_t>{};
  }
  std::string multigrid_source() const { return levels() ? levels()->source() : ""; }
  // The serial model solved (std::logic_error for a distributed problem).
  Model& model();
  Problem& problem() { return problem_; }
  // Seconds the last solve spent following mesh and constraint changes before iterating: new
  // vectors, the assembled tangent's sparsity, the multigrid levels (0 when nothing changed).
  double follow_seconds() const { return follow_seconds_; }
  // Times the preconditioner was filled (assembled tangent, multigrid levels at a state) since
  // the solver was made: reuse across Newton iterations and solves keeps it below their count.
  std::size_t preconditioner_fills() const { return preconditioner_.fills(); }
  // Times multigrid levels were made (a grid, aggregates or a cut through the bisection tree,
  // with their interpolations) since the solver was made: after a mesh change, or a change of
  // constraints the levels could not take over in place.
  std::size_t multigrid_builds() const { return preconditioner_.multigrid_builds(); }
  // How many of those were grid levels made from the earlier ones after an edit (on the grid of
  // the first build, only the node copies the edit reached found again: grid_multigrid.hpp).
  std::size_t multigrid_edits() const { return preconditioner_.multigrid_edits(); }
  // Times the assembled tangent's sparsity was made since the solver was made: once per change
  // of the mesh's elements, not for vertices moved alone (a cut's snap).
  std::size_t sparsity_builds() const { return preconditioner_.sparsity_builds(); }
  // How many of those were made from the earlier sparsity after an edit (only the touched
  // vertices' rows found again: tangent_assembly.hpp).
  std::size_t sparsity_edits() const { return preconditioner_.sparsity_edits(); }
  // Times every element's matrix was assembled into the tangent since the solver was made. After a
  // cut or a refinement, Newton's kept Galerkin levels on a tangent that does not depend on the
  // state (a linear material) take one made from the earlier one instead, with only the blocks
  // the edit touched computed (tangent_assembly.hpp).
  std::size_t tangent_assemblies() const { return preconditioner_.tangent_assemblies(); }
  // Times every piece of the mesh was labelled for the check that constraints hold each one
  // (piece_holding.hpp): once, then after edits only when a piece split off, pieces were joined
  // or a piece is loose (-static_rebuild_after_edits: after every change of the elements).
  std::size_t piece_labellings() const { return piece_holding_ ? piece_holding_->whole_labellings() : 0; }
  // The mesh's bisection hierarchy, once it has one (a mesh first refined after the solver was
  // made): the next levels, made after that refinement, coarsen along it.
  void use_hierarchy(const RefinementHierarchy* hierarchy) { preconditioner_.use_hierarchy(hierarchy); }

 private:
  // Solves `problem`, or `owned` when it is null, whose serial model is `model` (null on ranks),
  // with "mg" levels from `levels`.
  StaticSolver(std::unique_ptr<ModelProblem> owned, Problem* problem, Model* model,
               std::unique_ptr<LevelSource> levels, StaticOptions options);
  const Multigrid* levels() const { return preconditioner_.multigrid(); }
  void create_objects();
  // After a mesh change: new vectors if the size changed (same solver objects, so a user's
  // handle and options survive), the preconditioner's structures following the change.
  void follow_mesh_changes();
  // The solver objects reset onto new structures (new vectors if `resized`).
  void reset_objects(bool resized);
  // Leaves the KSP/SNES without callbacks into this solver, for handles that outlive it.
  void leave_solver_objects() noexcept;
  PC pc() const;
  // After the common start (solve()): the method's iterations, their count and reason in `result`.
  void solve_linear(SolveResult& result);
  void solve_nonlinear(SolveResult& result);
  // One SNESSolve from the state, its iterations added to the counts.
  void run_snes(SNESConvergedReason& reason, PetscInt& iterations, PetscInt& linear);
  void finish(SolveResult& result, double start_seconds, double start_flops);

  static PetscErrorCode residual_callback(SNES, Vec x, Vec F, void* context);
  static PetscErrorCode objective_callback(SNES, Vec x, PetscReal* value, void* context);
  static PetscErrorCode jacobian_callback(SNES, Vec x, Mat J, Mat P, void* context);
  static PetscErrorCode descent_direction_callback(SNESLineSearch, Vec u, Vec step, PetscBool* changed,
                                                   void* context);

  std::unique_ptr<ModelProblem> owned_problem_;  // made for a Model
  Problem& problem_;
  Model* model_;  // the serial model, or null on a distributed problem
  StaticOptions options_;
  SolverOptions option_database_;  // read by the PETSc objects below
  PreconditionerState preconditioner_;
  KspHandle ksp_;    // linear CG only
  SnesHandle snes_;  // nonlinear methods only
  VecHandle residual_;
  std::uint64_t generation_ = 0;
  ConvergenceTest convergence_{problem_};
  double system_scale_ = 1;  // CG and SNES see J, F and the energy divided by it (the force scale)
  double follow_seconds_ = 0;
  // Whether every piece of the body is held (checked before each solve; serial models).
  std::optional<PieceHolding> piece_holding_;
};

// Registers snede's line searches with PETSc (idempotent): snede_newton, snede_secant.
void register_line_searches();

}  // namespace snede
