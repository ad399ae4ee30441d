#include "solvers/dynamic_relaxation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/norms.hpp"
#include "core/rank_agreement.hpp"
#include "core/petsc_util.hpp"
#include "problem/model_problem.hpp"

namespace snede {
namespace {

// ---- Helpers of DynamicRelaxation -------------------------------------------------------

// Restores TS max steps (the user's cap, -<prefix>ts_max_steps) however a solve ends.
class MaxStepsGuard {
 public:
  MaxStepsGuard(TS ts, PetscInt cap) : ts_(ts), cap_(cap) {}
  ~MaxStepsGuard() { TSSetMaxSteps(ts_, cap_); }

 private:
  TS ts_;
  PetscInt cap_;
};

}  // namespace

std::string blow_up_failure(Vec u) {
  const double norm = vec_norm(u);
  if (!std::isfinite(norm)) return "DIVERGED_NONFINITE_STATE";
  return norm > 1e15 ? "DIVERGED_BLOW_UP" : "";
}

// ---- DynamicRelaxation --------------------------------------------------------------------

DynamicRelaxation::DynamicRelaxation(Model& model, const DynamicRelaxationOptions& options)
    : DynamicRelaxation(std::make_unique<ModelProblem>(model), nullptr, options) {}

DynamicRelaxation::DynamicRelaxation(Problem& problem, const DynamicRelaxationOptions& options)
    : DynamicRelaxation(nullptr, &problem, options) {}

DynamicRelaxation::DynamicRelaxation(std::unique_ptr<Problem> owned, Problem* problem,
                                     const DynamicRelaxationOptions& options)
    : owned_problem_(std::move(owned)),
      problem_(problem ? *problem : *owned_problem_),
      option_database_(options.options_prefix, options.petsc_options) {
  InputDigest options_digest;
  for (const auto& [name, value] : options.petsc_options) options_digest.add(name).add(value);
  RankAgreement("DynamicRelaxation")
      .input("damping", options.damping)
      .input("dt", options.dt.value_or(0.0))
      .input("options_prefix", options.options_prefix)
      .input("petsc_options", options_digest)
      .require(problem_.comm());
  options.validate();  // after the agreement, so that every rank gives the same verdict
  try {
    generation_ = problem_.generation();
    Vec u = problem_.state();
    SNEDE_PETSC(VecDuplicate(u, velocity_.out()));
    SNEDE_PETSC(VecZeroEntries(velocity_));
    problem_.add_carried_field(velocity_.slot());  // follows cuts and refinements like the state
    SNEDE_PETSC(VecDuplicate(u, inverse_mass_.out()));
    SNEDE_PETSC(VecDuplicate(u, residual_.out()));
    SNEDE_PETSC(TSCreate(problem_.comm(), ts_.out()));
    option_database_.use_for(ts_);
    TSAdapt adapt = nullptr;
    SNEDE_PETSC(TSGetAdapt(ts_, &adapt));
    option_database_.use_for(adapt);
    SNES snes = nullptr;  // unused by SS22, but TSSetFromOptions creates and configures it
    SNEDE_PETSC(TSGetSNES(ts_, &snes));
    option_database_.use_for(snes);
    const double default_dt = options.dt ? *options.dt : cfl_time_step();
    require(positive_finite(default_dt), "the CFL time step", "positive and finite (is the mesh empty?)", default_dt);
    set_up_ss22(ts_, {options.options_prefix, options.damping, default_dt, this, acceleration_callback,
                      post_step_callback, u, velocity_});
    option_database_.mark_read_options_used();
    follows_cfl_ = !options.dt && time_step() == default_dt;
  } catch (...) {
    problem_.remove_carried_field(velocity_.slot());  // the handles release the PETSc objects
    throw;
  }
}

DynamicRelaxation::~DynamicRelaxation() {
  problem_.remove_carried_field(velocity_.slot());
  TSSetApplicationContext(ts_, nullptr);  // a petsc4py handle may outlive this solver
  TSSetRHSFunction(ts_, nullptr,
                   [](TS, PetscReal, Vec, Vec, void*) { return orphaned_callback_error("DynamicRelaxation"); }, nullptr);
}

double DynamicRelaxation::time_step() const {
  PetscReal dt = 0;
  SNEDE_PETSC(TSGetTimeStep(ts_, &dt));
  return dt;
}

void DynamicRelaxation::set_time_step(double dt) {
  require(positive_finite(dt), "dt", "positive and finite", dt);
  SNEDE_PETSC(TSSetTimeStep(ts_, dt));
  follows_cfl_ = false;
}

std::vector<double> DynamicRelaxation::velocity() {
  reissue_sizes_if_mesh_changed();
  return vec_values(velocity_);
}

void DynamicRelaxation::set_velocity(std::span<const double> values) {
  reissue_sizes_if_mesh_changed();
  for (double x : values)
    if (!std::isfinite(x)) throw std::invalid_argument("velocity must be finite");
  set_vec_values(velocity_, values);
}

void DynamicRelaxation::reissue_sizes_if_mesh_changed() {
  if (generation_ == problem_.generation()) return;
  // The mesh changed size (a cut or a refinement): the model has carried the velocity over
  // like the displacement (a copy moves with its original, a midpoint with its edge); the
  // same TS takes the new vectors, so a user's handle and options survive.
  inverse_mass_.reset();
  residual_.reset();
  Vec u = problem_.state();
  SNEDE_PETSC(VecDuplicate(u, inverse_mass_.out()));
  SNEDE_PETSC(VecDuplicate(u, residual_.out()));
  SNEDE_PETSC(TSReset(ts_));
  SNEDE_PETSC(TS2SetSolution(ts_, u, velocity_));
  generation_ = problem_.generation();
  if (follows_cfl_) SNEDE_PETSC(TSSetTimeStep(ts_, cfl_time_step()));
}

void DynamicRelaxation::prepare_state() {
  // Constraints may have been set between calls: put u on them and let v move only along them.
  problem_.enforce_constraints(problem_.state());
  problem_.project_onto_allowed_motions(velocity_);
  // Lumped masses (§2.5), recomputed per call since elements may change without a size change.
  problem_.inverse_lumped_mass(inverse_mass_);
}

SolveResult DynamicRelaxation::step(int n) {
  RankAgreement("DynamicRelaxation.step").input("n", n).require(problem_.comm());
  require(n >= 0, "the number of steps", "≥ 0", n);
  return advance(n, Mode::steps, 0);
}

SolveResult DynamicRelaxation::run(double rtol, int max_steps) {
  RankAgreement("DynamicRelaxation.run").input("rtol", rtol).input("max_steps", max_steps).require(problem_.comm());
  require(positive_finite(rtol), "rtol", "positive and finite", rtol);
  require(max_steps >= 0, "max_steps", "≥ 0", max_steps);
  return advance(max_steps, Mode::relaxation, rtol);
}

double DynamicRelaxation::tolerance(double reaction_norm) const {
  return mode_ == Mode::relaxation ? stopping_.tolerance(external_norm_, reaction_norm) : 0;
}

SolveResult DynamicRelaxation::advance(PetscInt n_steps, Mode mode, double rtol) {
  const ExclusiveUse::Claim claim = problem_.exclusive_use().claim("a dynamic relaxation");
  reissue_sizes_if_mesh_changed();
  prepare_state();
  SolveResult result;
  const double start = wall_seconds(), start_flops = logged_flops();
  mode_ = mode;
  stopping_.criterion = StoppingCriterion::with_reactions;
  stopping_.rtol = rtol;
  stopping_.force_scale = problem_.force_scale();
  stopping_.n_dofs = static_cast<double>(problem_.n_global_dofs());
  external_norm_ = problem_.external_force_norm();
  history_.clear();
  failure_.clear();
  converged_ = false;

  Vec u = problem_.state();
  bool already_converged = false;
  if (mode == Mode::relaxation) {
    already_converged = converged_at(u);
    result.initial_residual_norm = checked_residual_norm_;
  }
  if (!already_converged) result.iterations = static_cast<int>(take_steps(n_steps));
  if (mode == Mode::steps) result.initial_residual_norm = history_.empty() ? 0 : history_.front();

  // The verdict is checked on the final state.
  const ResidualCheck check = problem_.residual(u, residual_);
  result.residual_norm = vec_norm(residual_);
  result.tolerance = tolerance(problem_.last_reaction_norm());
  std::string why;
  if (!failure_.empty()) {
    result.reason = failure_;
  } else if (!check.finite || !std::isfinite(result.residual_norm)) {
    result.reason = "DIVERGED_NONFINITE_STATE";
  } else if (!(why = problem_.inadmissible(u)).empty()) {
    result.reason = why;
  } else if (mode == Mode::relaxation) {
    result.converged = already_converged || converged_;
    result.reason = result.converged ? "CONVERGED_FNORM_ABS" : "DIVERGED_MAX_IT";
  } else {
    TSConvergedReason reason = TS_CONVERGED_ITERATING;
    SNEDE_PETSC(TSGetConvergedReason(ts_, &reason));
    result.converged = true;
    result.reason = TSConvergedReasons[reason];
  }
  result.energy = problem_.energy(u);
  result.residual_history = history_;
  result.seconds = wall_seconds() - start;
  result.flops = logged_flops() - start_flops;
  return result;
}

PetscInt DynamicRelaxation::take_steps(PetscInt n_steps) {
  PetscInt cap = 0, first = 0, last = 0;
  SNEDE_PETSC(TSGetMaxSteps(ts_, &cap));
  SNEDE_PETSC(TSGetStepNumber(ts_, &first));
  PetscInt target = n_steps > PETSC_MAX_INT - first ? PETSC_MAX_INT : first + n_steps;
  if (mode_ != Mode::stability_trial) target = std::min(target, cap);
  {
    MaxStepsGuard restore(ts_, cap);
    SNEDE_PETSC(TSSetMaxSteps(ts_, target));
    SNEDE_PETSC(TSSolve(ts_, nullptr));
  }
  option_database_.mark_read_options_used();  // a solve reads more (-ts_view)
  SNEDE_PETSC(TSGetStepNumber(ts_, &last));
  return last - first;
}

bool DynamicRelaxation::converged_at(Vec u) {
  const ResidualCheck check = problem_.residual(u, residual_);
  checked_residual_norm_ = vec_norm(residual_);
  return check.finite && checked_residual_norm_ <= tolerance(problem_.last_reaction_norm()) &&
         problem_.inadmissible(u).empty();
}

void DynamicRelaxation::after_step() {
  Vec u = problem_.state();
  if (mode_ != Mode::stability_trial) history_.push_back(last_residual_norm_);
  if (failure_.empty()) failure_ = blow_up_failure(u);
  if (!failure_.empty()) {
    SNEDE_PETSC(TSSetConvergedReason(ts_, TS_DIVERGED_STEP_REJECTED));
    return;
  }
  // The force of this step was evaluated at u_n; confirm at u_{n+1} before stopping.
  if (mode_ == Mode::relaxation && last_residual_norm_ <= last_tolerance_ && converged_at(u)) {
    converged_ = true;
    SNEDE_PETSC(TSSetConvergedReason(ts_, TS_CONVERGED_USER));
  }
}

double DynamicRelaxation::critical_time_step(double flop_budget, double initial, double reduction, int min_steps) {
  require(positive_finite(flop_budget), "flop_budget", "positive and finite", flop_budget);
  require(initial == 0 || positive_finite(initial), "initial", "positive and finite (or 0 for the CFL estimate)",
          initial);
  require(reduction > 0 && reduction < 1, "reduction", "in (0, 1)", reduction);
  require(min_steps >= 1, "min_steps", "≥ 1", min_steps);
  if (problem_.every_dof_prescribed())
    throw std::invalid_argument("every displacement is prescribed: nothing can vibrate, no step is critical");
  reissue_sizes_if_mesh_changed();
  prepare_state();
  const double flops_per_step = problem_.flops_per_residual();
  const auto trial_steps = static_cast<PetscInt>(std::max<double>(min_steps, std::ceil(flop_budget / flops_per_step)));

  // Everything a trial changes, restored after each trial and at the end.
  Vec u = problem_.state();
  const std::vector<double> u0 = vec_values(u), v0 = vec_values(velocity_);
  const double dt0 = time_step(), damping0 = damping();
  PetscReal t0 = 0;
  PetscInt steps0 = 0;
  SNEDE_PETSC(TSGetTime(ts_, &t0));
  SNEDE_PETSC(TSGetStepNumber(ts_, &steps0));
  auto restore = [&] {
    set_vec_values(u, u0);
    set_vec_values(velocity_, v0);
    SNEDE_PETSC(TSSetTime(ts_, t0));
    SNEDE_PETSC(TSSetStepNumber(ts_, steps0));
    SNEDE_PETSC(TSSetTimeStep(ts_, dt0));
    set_ss22_damping(ts_, damping0);
  };
  auto stable = [&](double dt) {
    restore();
    set_ss22_damping(ts_, 0.0);
    SNEDE_PETSC(TSSetTimeStep(ts_, dt));
    mode_ = Mode::stability_trial;
    failure_.clear();
    take_steps(trial_steps);
    return failure_.empty();
  };

  const double factor = 1 - reduction;
  const int max_trials = 60;  // 0.85⁶⁰ ≈ 6·10⁻⁵
  double dt = initial > 0 ? initial : cfl_time_step();
  try {
    if (stable(dt)) {
      int trial = 0;
      for (; trial < max_trials && stable(dt / factor); ++trial) dt /= factor;
      if (trial == max_trials)
        throw std::runtime_error("no blow-up even at " + std::to_string(dt) + " s: nothing vibrates");
    } else {
      int trial = 0;
      for (; trial < max_trials && !stable(dt * factor); ++trial) dt *= factor;
      if (trial == max_trials)
        throw std::runtime_error("blow-up even at " + std::to_string(dt * factor) + " s: the state itself diverges");
      dt *= factor;
    }
  } catch (...) {
    restore();
    failure_.clear();
    throw;
  }
  restore();
  failure_.clear();
  return dt;
}

PetscErrorCode DynamicRelaxation::acceleration_callback(TS, PetscReal, Vec u, Vec a, void* context) {
  return petsc_callback("snede dynamic relaxation force", [&] {
    auto* self = &callback_owner<DynamicRelaxation>(context, "DynamicRelaxation");
    Problem& problem = self->problem_;
    const ResidualCheck check = problem.residual(u, a);  // F(u) = P∇Π(u) on u's constraints
    self->last_residual_norm_ = vec_norm(a);
    self->last_tolerance_ = self->tolerance(problem.last_reaction_norm());
    if (self->failure_.empty()) {
      if (!check.finite) self->failure_ = "DIVERGED_NONFINITE_STATE";
      else if (check.inverted && self->mode_ != Mode::stability_trial) self->failure_ = "DIVERGED_INVERTED_ELEMENTS";
    }
    // a = −M⁻¹ P ∇Π(u): the net force on the allowed motions over the lumped mass.
    problem.project_onto_allowed_motions(a);
    SNEDE_PETSC(VecPointwiseMult(a, self->inverse_mass_, a));
    SNEDE_PETSC(VecScale(a, -1.0));
  });
}

PetscErrorCode DynamicRelaxation::post_step_callback(TS ts) {
  return petsc_callback("snede dynamic relaxation post-step", [&] {
    void* context = nullptr;
    SNEDE_PETSC(TSGetApplicationContext(ts, &context));
    callback_owner<DynamicRelaxation>(context, "DynamicRelaxation").after_step();
    stop_if_interrupted();
  });
}

}  // namespace snede
