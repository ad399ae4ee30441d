// The line searches of §4.4.2 for nonlinear CG, registered as PETSc line-search types:
//   snede_newton  Newton's method on g(α) = ∇Π(x + αd)·d, with g'(α) = dᵀK(x + αd)d;
//   snede_secant  the same with g' replaced by the secant through the last two iterates
//                 (4.9), the first step still using K(x)d.
// The thesis's third variant, the scale-dependent secant (the first g' also a secant, from
// α₋₁), is PETSc's `cp` line search: a secant iteration on the directional derivative
// F(x − λy)·y starting from λ = 0 and the initial step length (-snes_linesearch_damping).
// PETSc writes the step as x − λy, so d = −y. Iterations stop when |δ| < rtol |δ₀|
// (-snes_linesearch_rtol, ε_newton) or after -snes_linesearch_max_it steps (j_max). A step
// into an inverted or overflowing state is halved back towards the last admissible one.
#include <petsc/private/linesearchimpl.h>

#include <cmath>
#include <stdexcept>

#include "core/error.hpp"
#include "solvers/static_solver.hpp"

namespace snede {
namespace {

enum class Slope { tangent, secant };

// How many times a step into an inadmissible state is halved before the search fails.
constexpr int max_halvings = 30;

void apply_line_search(SNESLineSearch ls, Slope slope_kind) {
  SNES snes = nullptr;
  SNEDE_PETSC(SNESLineSearchGetSNES(ls, &snes));
  // K(x)d comes from the SNES's own Jacobian (a shell whose callback sets the linearisation
  // point), so the search serves any problem that gives one: serial or distributed.
  Mat J = nullptr, P = nullptr;
  SNEDE_PETSC(SNESGetJacobian(snes, &J, &P, nullptr, nullptr));
  if (!J) throw std::logic_error("the snede line searches need the SNES's Jacobian (SNESSetJacobian)");
  Vec X, F, Y, W, G;
  SNEDE_PETSC(SNESLineSearchGetVecs(ls, &X, &F, &Y, &W, &G));
  PetscReal steptol, maxstep, rtol, atol, ltol;
  PetscInt max_its;
  SNEDE_PETSC(SNESLineSearchGetTolerances(ls, &steptol, &maxstep, &rtol, &atol, &ltol, &max_its));

  VecHandle d, Kd;
  SNEDE_PETSC(VecDuplicate(Y, d.out()));
  SNEDE_PETSC(VecDuplicate(Y, Kd.out()));
  SNEDE_PETSC(VecCopy(Y, d));
  SNEDE_PETSC(VecScale(d, -1.0));

  auto tangent_slope = [&](Vec at) {
    SNEDE_PETSC(SNESComputeJacobian(snes, at, J, P));
    SNEDE_PETSC(MatMult(J, d, Kd));
    PetscScalar value = 0;
    SNEDE_PETSC(VecDot(d, Kd, &value));
    return value;
  };
  auto directional_derivative = [&](Vec gradient) {
    PetscScalar value = 0;
    SNEDE_PETSC(VecDot(gradient, d, &value));
    return value;
  };

  double alpha = 0, alpha_previous = 0, g_previous = 0, first_update = 0;
  double g = directional_derivative(F);
  bool evaluated_at_alpha = true;  // G (or F for α = 0) holds the gradient at alpha
  PetscBool domain_error = PETSC_FALSE;
  for (PetscInt j = 0; j < max_its; ++j) {
    if (j > 0) {
      // A trial step that inverts an element (or overflows) is halved back towards the
      // last admissible α; the first admissible point ends the search.
      bool shortened = false;
      for (int halving = 0; halving <= max_halvings; ++halving) {
        SNEDE_PETSC(VecWAXPY(W, alpha, d, X));
        SNEDE_PETSC(SNESComputeFunction(snes, W, G));
        SNEDE_PETSC(SNESGetFunctionDomainError(snes, &domain_error));
        if (!domain_error) break;
        alpha = 0.5 * (alpha + alpha_previous);
        shortened = true;
      }
      if (domain_error) break;
      evaluated_at_alpha = true;
      if (shortened) break;
      g = directional_derivative(G);
    }
    double slope;
    if (slope_kind == Slope::secant && j > 0) {
      slope = (g - g_previous) / (alpha - alpha_previous);
    } else {
      SNEDE_PETSC(VecWAXPY(W, alpha, d, X));
      slope = tangent_slope(W);
    }
    if (!(slope > 0) || !std::isfinite(slope)) break;  // not convex along d: keep what we have
    const double update = g / slope;
    if (j == 0) first_update = update;
    if (j > 0 && std::abs(update) < rtol * std::abs(first_update)) break;
    alpha_previous = alpha;
    g_previous = g;
    alpha -= update;
    evaluated_at_alpha = false;
  }
  d.reset();
  Kd.reset();
  if (domain_error || alpha <= 0 || !std::isfinite(alpha)) {
    SNEDE_PETSC(SNESLineSearchSetReason(ls, domain_error ? SNES_LINESEARCH_FAILED_DOMAIN : SNES_LINESEARCH_FAILED_REDUCT));
    return;
  }
  // x ← x + αd = x − αy, with its gradient.
  SNEDE_PETSC(VecAXPY(X, -alpha, Y));
  if (evaluated_at_alpha && alpha != 0) {
    SNEDE_PETSC(VecCopy(G, F));
  } else {
    SNEDE_PETSC(SNESComputeFunction(snes, X, F));
    SNEDE_PETSC(SNESGetFunctionDomainError(snes, &domain_error));
    if (domain_error) {
      SNEDE_PETSC(SNESLineSearchSetReason(ls, SNES_LINESEARCH_FAILED_DOMAIN));
      return;
    }
  }
  SNEDE_PETSC(SNESLineSearchSetLambda(ls, alpha));
  SNEDE_PETSC(SNESLineSearchComputeNorms(ls));
}

PetscErrorCode apply_newton(SNESLineSearch ls) {
  return petsc_callback("snede_newton line search", [&] { apply_line_search(ls, Slope::tangent); });
}

PetscErrorCode apply_secant(SNESLineSearch ls) {
  return petsc_callback("snede_secant line search", [&] { apply_line_search(ls, Slope::secant); });
}

// j_max and ε_newton defaults (tunable with -snes_linesearch_max_it / _rtol).
void set_defaults(SNESLineSearch ls) {
  ls->max_its = 8;
  ls->rtol = 1e-2;
}

PetscErrorCode create_newton(SNESLineSearch ls) {
  ls->ops->apply = apply_newton;
  set_defaults(ls);
  return 0;
}

PetscErrorCode create_secant(SNESLineSearch ls) {
  ls->ops->apply = apply_secant;
  set_defaults(ls);
  return 0;
}

}  // namespace

void register_line_searches() {
  static bool registered = false;
  if (registered) return;
  SNEDE_PETSC(SNESLineSearchRegister("snede_newton", create_newton));
  SNEDE_PETSC(SNESLineSearchRegister("snede_secant", create_secant));
  registered = true;
}

}  // namespace snede
