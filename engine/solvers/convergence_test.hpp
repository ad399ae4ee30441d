// snede's stopping criterion (§6.6, problem/stopping.hpp) as the convergence tests of a static
// solve's SNES and KSP: the residual in newtons against the rule's tolerance, its history, NaN
// and overflow as divergence, and a stalled Newton line search ended at once so that the
// solver's full-step finish takes over.
#pragma once

#include <petscksp.h>
#include <petscsnes.h>

#include <optional>
#include <vector>

#include "problem/problem.hpp"
#include "problem/stopping.hpp"

namespace snede {

class ConvergenceTest {
 public:
  explicit ConvergenceTest(Problem& problem) : problem_(problem) {}

  // At the start of a solve: `rule` scaled to the problem (its force scale and unknowns) and the
  // external forces of now. Returns the system scale, the force scale E·t·H (E·H² in 3D) or 1
  // when that is not finite: the solvers see the system divided by it, so that their dot
  // products stay in range whatever the units (E = 1e155 Pa overflows p·Ap otherwise), and the
  // tests multiply their norms back.
  double start(const StoppingRule& rule);
  // With the starting residual's norm, after the residual was computed: the relative criterion's
  // ε‖r(u₀)‖. `fixed_reactions`: the reactions of now are those of the whole solve (linear CG,
  // whose iterates are not the state).
  void anchor(double initial_norm, bool fixed_reactions);
  double tolerance() const;
  const std::vector<double>& history() const { return history_; }

  // Makes `snes` or `ksp` stop by this test; `leave` makes it fail for handles that outlive it.
  void install(SNES snes);
  void install(KSP ksp);
  static void leave(SNES snes);
  static void leave(KSP ksp);

 private:
  static PetscErrorCode snes_test(SNES, PetscInt it, PetscReal xnorm, PetscReal snorm, PetscReal fnorm,
                                  SNESConvergedReason* reason, void* context);
  static PetscErrorCode ksp_test(KSP, PetscInt it, PetscReal rnorm, KSPConvergedReason* reason, void* context);

  Problem& problem_;
  StoppingRule rule_;
  double external_norm_ = 0;
  double system_scale_ = 1;
  std::optional<double> fixed_reaction_norm_;
  std::vector<double> history_;
};

}  // namespace snede
