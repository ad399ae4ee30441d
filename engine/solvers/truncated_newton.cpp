#include "solvers/truncated_newton.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"

namespace snede {
namespace {

// With a PC set up anew at every Newton iteration (GAMG on an assembled tangent, matrix-free
// bisection levels), a few accurate Newton steps cost less than many truncated ones: at
// 98 304 neo-Hookean tetrahedra 9 iterations (inner rtol 1e-3) against 37–44 with
// Eisenstat-Walker. Galerkin levels kept through the solve cost nothing per iteration: there
// 1e-2 took as many Newton iterations and a quarter fewer flops in the cut loops, and the same
// on the static block (issue 49; docs/results/interactive.md). Eisenstat–Walker took half the
// CG in the loops but four times the Newton iterations on the static block.
constexpr double set_up_levels_inner_rtol = 1e-3;
constexpr double kept_levels_inner_rtol = 1e-2;
// After a line-search failure Newton tries at most this many full steps, and keeps them only
// if they meet the stopping criterion (quadratic convergence needs a handful).
constexpr PetscInt newton_finish_steps = 10;

}  // namespace

bool is_line_search_newton(SNES snes) {
  PetscBool same = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(snes), SNESNEWTONLS, &same));
  return same;
}

void choose_forcing(SNES snes, const SolverOptions& options, const std::string& prefix, bool preconditioned,
                    bool levels_kept) {
  // A forcing the user chose is left alone.
  if (options.string_option(prefix + "snes_ksp_ew") || options.string_option(prefix + "ksp_rtol")) return;
  KSP inner = nullptr;
  SNEDE_PETSC(SNESGetKSP(snes, &inner));
  // Without a PC the inner CG stops early (Eisenstat–Walker), tightening as the outer
  // converges, and where the tangent is indefinite (far from the solution of a soft body) CG
  // stops at the negative curvature and its iterate so far is used as the search direction.
  SNEDE_PETSC(SNESKSPSetUseEW(snes, preconditioned ? PETSC_FALSE : PETSC_TRUE));
  if (!preconditioned) return;
  const double inner_rtol = levels_kept ? kept_levels_inner_rtol : set_up_levels_inner_rtol;
  SNEDE_PETSC(KSPSetTolerances(inner, inner_rtol, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT));
}

void make_descent_direction(SNESLineSearch line_search, Vec step, Problem& problem, Multigrid* levels) {
  SNES snes = nullptr;
  Vec residual = nullptr;
  SNEDE_PETSC(SNESLineSearchGetSNES(line_search, &snes));
  SNEDE_PETSC(SNESGetFunction(snes, &residual, nullptr, nullptr));
  // The step onto the allowed motions (6.7): a preconditioner that is not itself projected
  // (Jacobi's diagonal scaling, GAMG, multigrid) gives a truncated CG iterate components off a
  // sliding vertex's line, and the update would leave it (a box with 49 vertices sliding along
  // random directions: Jacobi's Newton stopped with DIVERGED_LINE_SEARCH, mg took 39 iterations
  // of a linear problem where no preconditioner took 5). The slope F·step is unchanged, F
  // being projected already.
  problem.project_onto_allowed_motions(step);
  // An indefinite multigrid preconditioner is made positive definite for the next Newton
  // steps where its levels can be (bisection_multigrid.hpp).
  KSP ksp = nullptr;
  KSPConvergedReason linear_reason = KSP_CONVERGED_ITERATING;
  SNEDE_PETSC(SNESGetKSP(snes, &ksp));
  SNEDE_PETSC(KSPGetConvergedReason(ksp, &linear_reason));
  // Newton moves to u − λ·step: downhill iff F·step > 0 (F = ∇Π, §2.4.3).
  PetscScalar slope = 0;
  SNEDE_PETSC(VecDot(residual, step, &slope));
  if ((linear_reason == KSP_DIVERGED_INDEFINITE_PC || !(slope > 0)) && levels) levels->prefer_positive_definite();
  if (slope > 0) return;
  // Truncated Newton (§2.4.3) stops CG at the first direction of non-positive curvature and
  // keeps its iterate so far, or at the first iteration takes the steepest descent. PETSc's CG
  // tests only for a change of the curvature's sign: when the very first direction has negative
  // curvature (a closed membrane hanging under gravity, whose compressed part wrinkles), it
  // steps along it backwards and returns an uphill direction, along which the energy line
  // search can only fail (DIVERGED_LINE_SEARCH after 25 iterations on the liver's skin). Then
  // the (preconditioned) steepest descent, scaled by the magnitude of its curvature.
  PC pc = nullptr;
  Mat tangent = nullptr;
  SNEDE_PETSC(KSPGetPC(ksp, &pc));
  SNEDE_PETSC(KSPGetOperators(ksp, &tangent, nullptr));
  SNEDE_PETSC(PCApply(pc, residual, step));
  problem.project_onto_allowed_motions(step);
  SNEDE_PETSC(VecDot(residual, step, &slope));
  if (!(slope > 0)) {  // an indefinite preconditioner
    SNEDE_PETSC(VecCopy(residual, step));
    SNEDE_PETSC(VecDot(residual, step, &slope));
  }
  VecHandle tangent_times_step;
  SNEDE_PETSC(VecDuplicate(step, tangent_times_step.out()));
  SNEDE_PETSC(MatMult(tangent, step, tangent_times_step));
  PetscScalar curvature = 0;
  SNEDE_PETSC(VecDot(step, tangent_times_step, &curvature));
  if (curvature != 0 && std::isfinite(curvature)) SNEDE_PETSC(VecScale(step, slope / std::abs(curvature)));
}

void finish_with_full_steps(SNES snes, Vec u, PetscInt max_iterations, PetscInt iterations,
                            SNESConvergedReason& reason, const std::function<void()>& run) {
  // Near the solution the energy decrease of a Newton step falls below the round-off of Π
  // (summed over all elements), and the energy-based backtracking stops (DIVERGED_LINE_SEARCH)
  // short of the tolerance; a good preconditioner gets there in few iterations, while the
  // residual is still far above it. Full Newton steps converge quadratically there: a few
  // are tried, and kept only if they meet the criterion — otherwise the state goes back to
  // where the line search stopped, so the attempt never makes a result worse.
  // (PETSc reports some of these failures as DIVERGED_LOCAL_MIN when ‖Jᵀ F‖ is small.)
  const SNESConvergedReason stopped_by = reason;
  VecHandle stopped;
  SNEDE_PETSC(VecDuplicate(u, stopped.out()));
  SNEDE_PETSC(VecCopy(u, stopped));
  SNESLineSearch line_search = nullptr;
  SNESLineSearchType type = nullptr;
  SNEDE_PETSC(SNESGetLineSearch(snes, &line_search));
  SNEDE_PETSC(SNESLineSearchGetType(line_search, &type));
  const std::string previous = type;
  const PetscInt left = std::max<PetscInt>(0, max_iterations - iterations);
  SNEDE_PETSC(SNESLineSearchSetType(line_search, SNESLINESEARCHBASIC));
  SNEDE_PETSC(SNESSetTolerances(snes, 0.0, 0.0, 0.0, std::min(newton_finish_steps, left), -1));
  if (left > 0) run();
  SNEDE_PETSC(SNESSetTolerances(snes, 0.0, 0.0, 0.0, max_iterations, -1));
  SNEDE_PETSC(SNESLineSearchSetType(line_search, previous.c_str()));
  if (left == 0 || reason <= 0) {
    SNEDE_PETSC(VecCopy(stopped, u));
    reason = stopped_by;
  }
}

}  // namespace snede
