#include "solvers/convergence_test.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/interrupt.hpp"

namespace snede {
namespace {

// ‖F‖ changed by less than this fraction over a Newton iteration: a stalled line search.
constexpr double newton_stall = 1e-6;

}  // namespace

double ConvergenceTest::start(const StoppingRule& rule) {
  history_.clear();
  fixed_reaction_norm_.reset();
  external_norm_ = problem_.external_force_norm();
  // The force scale is a scan of the mesh: once per solve, not once per iteration.
  rule_ = rule;
  rule_.force_scale = problem_.force_scale();
  rule_.n_dofs = static_cast<double>(problem_.n_global_dofs());
  system_scale_ = std::isfinite(rule_.force_scale) && rule_.force_scale > 0 ? rule_.force_scale : 1.0;
  return system_scale_;
}

void ConvergenceTest::anchor(double initial_norm, bool fixed_reactions) {
  if (fixed_reactions) fixed_reaction_norm_ = problem_.last_reaction_norm();
  if (rule_.criterion != StoppingCriterion::relative) return;
  // A start already in equilibrium by (6.9) is converged with no iteration: ε‖r(u₀)‖ is out of
  // reach of a residual at round-off (Newton ended DIVERGED_LINE_SEARCH there, issue 38).
  StoppingRule equilibrium = rule_;
  equilibrium.criterion = StoppingCriterion::with_reactions;
  if (initial_norm <= equilibrium.tolerance(external_norm_, problem_.last_reaction_norm())) {
    rule_ = equilibrium;
    return;
  }
  rule_.initial_residual_norm = initial_norm;
}

double ConvergenceTest::tolerance() const {
  return rule_.tolerance(external_norm_, fixed_reaction_norm_.value_or(problem_.last_reaction_norm()));
}

void ConvergenceTest::install(SNES snes) { SNEDE_PETSC(SNESSetConvergenceTest(snes, snes_test, this, nullptr)); }

void ConvergenceTest::install(KSP ksp) { SNEDE_PETSC(KSPSetConvergenceTest(ksp, ksp_test, this, nullptr)); }

void ConvergenceTest::leave(SNES snes) { SNESSetConvergenceTest(snes, snes_test, nullptr, nullptr); }

void ConvergenceTest::leave(KSP ksp) { KSPSetConvergenceTest(ksp, ksp_test, nullptr, nullptr); }

PetscErrorCode ConvergenceTest::snes_test(SNES snes, PetscInt it, PetscReal xnorm, PetscReal snorm, PetscReal fnorm,
                                          SNESConvergedReason* reason, void* context) {
  return petsc_callback("snede stopping criterion", [&] {
    ConvergenceTest& self = callback_owner<ConvergenceTest>(context, "StaticSolver");
    stop_if_interrupted();
    // PETSc's default test catches NaN norms and the iteration limit.
    SNEDE_PETSC(SNESConvergedDefault(snes, it, xnorm, snorm, fnorm, reason, nullptr));
    fnorm *= self.system_scale_;  // the residual in newtons
    self.history_.push_back(fnorm);
    if (*reason < 0) return;
    const double tolerance = self.tolerance();
    if (!std::isfinite(tolerance)) {
      *reason = SNES_DIVERGED_FNORM_NAN;
      return;
    }
    *reason = fnorm <= tolerance ? SNES_CONVERGED_FNORM_ABS : SNES_CONVERGED_ITERATING;
    // A Newton iteration that leaves ‖F‖ as it was made no progress: the line search took a
    // vanishing step, which near the solution means the energy cannot show the decrease any
    // more (its round-off). Stop as a line-search failure, so that the full-step finish of the
    // static solver takes over now rather than after more stalled iterations. (A trust region
    // leaves ‖F‖ as it was at every step it rejects: that is no stall.)
    const std::vector<double>& history = self.history_;
    const std::size_t n = history.size();
    PetscBool line_search_newton = PETSC_FALSE;
    SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(snes), SNESNEWTONLS, &line_search_newton));
    if (*reason == SNES_CONVERGED_ITERATING && line_search_newton && it > 0 && n >= 2 &&
        std::abs(fnorm - history[n - 2]) <= newton_stall * history[n - 2])
      *reason = SNES_DIVERGED_LINE_SEARCH;
  });
}

PetscErrorCode ConvergenceTest::ksp_test(KSP, PetscInt /*iteration*/, PetscReal rnorm, KSPConvergedReason* reason,
                                         void* context) {
  return petsc_callback("snede stopping criterion", [&] {
    ConvergenceTest& self = callback_owner<ConvergenceTest>(context, "StaticSolver");
    stop_if_interrupted();
    rnorm *= self.system_scale_;  // the residual in newtons
    self.history_.push_back(rnorm);
    const double tolerance = self.tolerance();
    if (!std::isfinite(rnorm) || !std::isfinite(tolerance)) {
      *reason = KSP_DIVERGED_NANORINF;
      return;
    }
    // For a linear problem the CG residual b − Jδ is the equilibrium residual −F(u + δ).
    *reason = rnorm <= tolerance ? KSP_CONVERGED_ATOL : KSP_CONVERGED_ITERATING;
  });
}

}  // namespace snede
