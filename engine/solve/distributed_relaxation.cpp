#include "solve/distributed_relaxation.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/rank_agreement.hpp"
#include "core/petsc_util.hpp"
#include "solve/dynamic_relaxation.hpp"
#include "solve/ts_ss22.hpp"

namespace snede {

DistributedRelaxation::DistributedRelaxation(DistributedStatic& problem, double damping, double dt,
                                             const std::string& options_prefix)
    : problem_(problem) {
  RankAgreement("DistributedRelaxation")
      .input("damping", damping)
      .input("dt", dt)
      .input("options_prefix", options_prefix)
      .require(problem.comm());
  require_valid_damping(damping);
  require(dt == 0 || positive_finite(dt), "dt", "positive and finite (or 0 for the CFL estimate)", dt);
  Vec u = problem.state();
  SNEDE_PETSC(VecDuplicate(u, velocity_.out()));
  SNEDE_PETSC(VecZeroEntries(velocity_));
  SNEDE_PETSC(VecDuplicate(u, inverse_mass_.out()));
  SNEDE_PETSC(VecDuplicate(u, residual_.out()));
  problem.inverse_lumped_mass(inverse_mass_);
  const double step = dt > 0 ? dt : problem.cfl_time_step();
  require(positive_finite(step), "the CFL time step", "positive and finite (is the mesh empty?)", step);
  SNEDE_PETSC(TSCreate(problem.comm(), ts_.out()));
  set_up_ss22(ts_, {options_prefix, damping, step, this, acceleration_callback, post_step_callback, u, velocity_});
  stopping_.criterion = StoppingCriterion::with_reactions;
  stopping_.force_scale = problem.force_scale();
  stopping_.n_dofs = static_cast<double>(problem.n_global_dofs());
  external_norm_ = problem.external_force_norm();
}

DistributedRelaxation::~DistributedRelaxation() { TSSetApplicationContext(ts_, nullptr); }

double DistributedRelaxation::time_step() const {
  PetscReal dt = 0;
  SNEDE_PETSC(TSGetTimeStep(ts_, &dt));
  return dt;
}

SolveResult DistributedRelaxation::run(double rtol, int max_steps) {
  RankAgreement("DistributedRelaxation.run").input("rtol", rtol).input("max_steps", max_steps).require(problem_.comm());
  require(positive_finite(rtol), "rtol", "positive and finite", rtol);
  require(max_steps >= 0, "max_steps", "≥ 0", max_steps);
  const double start = wall_seconds();
  stopping_.rtol = rtol;
  failure_.clear();
  converged_ = false;
  SolveResult result;
  Vec u = problem_.state();
  bool admissible = problem_.residual(u, residual_);
  result.initial_residual_norm = vec_norm(residual_);
  converged_ = admissible && result.initial_residual_norm <= stopping_.tolerance(external_norm_, problem_.last_reaction_norm());
  if (!converged_) {
    PetscInt first = 0, last = 0;
    SNEDE_PETSC(TSGetStepNumber(ts_, &first));
    SNEDE_PETSC(TSSetMaxSteps(ts_, first + max_steps));
    SNEDE_PETSC(TSSolve(ts_, nullptr));
    SNEDE_PETSC(TSGetStepNumber(ts_, &last));
    result.iterations = static_cast<int>(last - first);
  }
  admissible = problem_.residual(u, residual_);
  result.residual_norm = vec_norm(residual_);
  result.tolerance = stopping_.tolerance(external_norm_, problem_.last_reaction_norm());
  if (!failure_.empty()) result.reason = failure_;
  else if (!admissible) result.reason = problem_.last_failure();
  else if (!std::isfinite(result.residual_norm)) result.reason = "DIVERGED_NONFINITE_STATE";
  else result.reason = converged_ ? "CONVERGED_FNORM_ABS" : "DIVERGED_MAX_IT";
  result.converged = result.reason == "CONVERGED_FNORM_ABS";
  result.energy = problem_.energy();
  result.seconds = wall_seconds() - start;
  return result;
}

void DistributedRelaxation::acceleration(Vec u, Vec a) {
  // a = −M⁻¹ P F(u): the net force on the free motions over the lumped mass.
  if (!problem_.residual(u, a) && failure_.empty()) failure_ = problem_.last_failure();
  last_residual_norm_ = vec_norm(a);
  last_reaction_norm_ = problem_.last_reaction_norm();
  problem_.zero_fixed_rows(a);
  SNEDE_PETSC(VecPointwiseMult(a, inverse_mass_, a));
  SNEDE_PETSC(VecScale(a, -1.0));
}

void DistributedRelaxation::after_step() {
  Vec u = problem_.state();
  if (failure_.empty()) failure_ = blow_up_failure(u);
  if (!failure_.empty()) {
    SNEDE_PETSC(TSSetConvergedReason(ts_, TS_DIVERGED_STEP_REJECTED));
    return;
  }
  // The force of this step was evaluated at u_n; confirm at u_{n+1} before stopping.
  if (last_residual_norm_ > stopping_.tolerance(external_norm_, last_reaction_norm_)) return;
  const bool admissible = problem_.residual(u, residual_);
  if (admissible && vec_norm(residual_) <= stopping_.tolerance(external_norm_, problem_.last_reaction_norm())) {
    converged_ = true;
    SNEDE_PETSC(TSSetConvergedReason(ts_, TS_CONVERGED_USER));
  }
}

PetscErrorCode DistributedRelaxation::acceleration_callback(TS, PetscReal, Vec u, Vec a, void* context) {
  return petsc_callback("snede distributed relaxation force", [&] {
    callback_owner<DistributedRelaxation>(context, "DistributedRelaxation").acceleration(u, a);
  });
}

PetscErrorCode DistributedRelaxation::post_step_callback(TS ts) {
  return petsc_callback("snede distributed relaxation post-step", [&] {
    void* context = nullptr;
    SNEDE_PETSC(TSGetApplicationContext(ts, &context));
    callback_owner<DistributedRelaxation>(context, "DistributedRelaxation").after_step();
  });
}

}  // namespace snede
