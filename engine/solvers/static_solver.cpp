#include "solvers/static_solver.hpp"

#include <petscdmshell.h>
#include <petsctime.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log_event.hpp"
#include "core/norms.hpp"
#include "core/petsc_util.hpp"
#include "solvers/failed_solve.hpp"
#include "solvers/truncated_newton.hpp"

namespace snede {
namespace {

StaticOptions checked(StaticOptions options, const Problem& problem) {
  require_valid(options, std::holds_alternative<LinearElastic>(problem.material()), problem.comm());
  return options;
}

}  // namespace

StaticSolver::StaticSolver(Model& model, StaticOptions options, const RefinementHierarchy* hierarchy)
    : StaticSolver(std::make_unique<ModelProblem>(model), nullptr, &model, mesh_level_source(model, hierarchy),
                   std::move(options)) {}

StaticSolver::StaticSolver(DistributedStatic& problem, StaticOptions options)
    : StaticSolver(nullptr, &problem, nullptr, rank_level_source(problem), std::move(options)) {}

StaticSolver::StaticSolver(std::unique_ptr<ModelProblem> owned, Problem* problem, Model* model,
                           std::unique_ptr<LevelSource> levels, StaticOptions options)
    : owned_problem_(std::move(owned)),
      problem_(problem ? *problem : *owned_problem_),
      model_(model),
      options_(checked(std::move(options), problem_)),
      option_database_(options_.options_prefix, options_.petsc_options),
      preconditioner_(problem_, std::move(levels), option_database_, options_) {
  if (model_) {
    // The reference (-static_rebuild_after_edits) labels the pieces from scratch after each edit too.
    if (preconditioner_.rebuild_after_edits()) piece_holding_.emplace(model_->body().mesh());
    else piece_holding_.emplace(model_->body().mesh(), PieceHolding::FollowEdits{});
  }
  register_line_searches();
  create_objects();  // on a bad option the handles release what was made
}

StaticSolver::~StaticSolver() { leave_solver_objects(); }

void StaticSolver::leave_solver_objects() noexcept {
  // A petsc4py handle may outlive this solver or its objects: leave its callbacks without a
  // context.
  constexpr const char* owner = "StaticSolver";
  if (snes_) {
    SNESSetApplicationContext(snes_, nullptr);  // the line searches find their solver here
    SNESSetFunction(snes_, nullptr, [](SNES, Vec, Vec, void*) { return orphaned_callback_error(owner); }, nullptr);
    SNESSetObjective(snes_, [](SNES, Vec, PetscReal*, void*) { return orphaned_callback_error(owner); }, nullptr);
    if (options_.method == StaticMethod::newton)
      SNESSetJacobian(snes_, nullptr, nullptr, [](SNES, Vec, Mat, Mat, void*) { return orphaned_callback_error(owner); },
                      nullptr);
    ConvergenceTest::leave(snes_);
    SNESLineSearch line_search = nullptr;
    SNESGetLineSearch(snes_, &line_search);
    SNESLineSearchSetPreCheck(
        line_search, [](SNESLineSearch, Vec, Vec, PetscBool*, void*) { return orphaned_callback_error(owner); }, nullptr);
  }
  if (ksp_) ConvergenceTest::leave(ksp_);
  KSP inner = ksp_;
  if (!inner && snes_) SNESGetKSP(snes_, &inner);
  if (!inner) return;
  // Newton's Eisenstat–Walker hooks on its KSP point to the SNES, and multigrid levels' operators
  // (bisection levels' shells) to models this solver owns.
  KSPSetPreSolve(inner, nullptr, nullptr);
  KSPSetPostSolve(inner, nullptr, nullptr);
  PC pc = nullptr;
  if (KSPGetPC(inner, &pc) == 0) PCSetType(pc, PCNONE);
}

KSP StaticSolver::ksp() const {
  if (ksp_) return ksp_;
  KSP inner = nullptr;
  SNESGetKSP(snes_, &inner);
  return inner;
}

PC StaticSolver::pc() const {
  PC pc = nullptr;
  SNEDE_PETSC(KSPGetPC(ksp(), &pc));
  return pc;
}

void StaticSolver::create_objects() {
  generation_ = problem_.generation();
  preconditioner_.make_missing_levels();  // before the operators: Galerkin levels need the assembled tangent
  SNEDE_PETSC(VecDuplicate(problem_.state(), residual_.out()));
  const char* prefix = options_.options_prefix.c_str();
  if (options_.method == StaticMethod::linear_cg) {
    SNEDE_PETSC(KSPCreate(problem_.comm(), ksp_.out()));
    option_database_.use_for(ksp_);
    SNEDE_PETSC(KSPSetOptionsPrefix(ksp_, prefix));
    SNEDE_PETSC(KSPSetType(ksp_, KSPCG));
    preconditioner_.configure(pc());
    SNEDE_PETSC(KSPSetOperators(ksp_, problem_.tangent(), preconditioner_.matrix()));
    SNEDE_PETSC(KSPSetTolerances(ksp_, 0.0, 0.0, PETSC_DEFAULT, options_.max_iterations));
    convergence_.install(ksp_);
    // The criterion is on the equilibrium residual b − Jδ itself: with a preconditioner CG
    // would otherwise hand the test the preconditioned norm ‖B(b − Jδ)‖. Without one the
    // natural norm √(r·r) is that norm, from the dot product CG takes anyway: no VecNorm per
    // iteration (a tenth of a small solve, the 2D needle's, issue 33).
    SNEDE_PETSC(KSPSetNormType(ksp_, preconditioner_.type() == PCNONE ? KSP_NORM_NATURAL : KSP_NORM_UNPRECONDITIONED));
    SNEDE_PETSC(KSPSetFromOptions(ksp_));
    option_database_.mark_read_options_used();
    return;
  }
  SNEDE_PETSC(SNESCreate(problem_.comm(), snes_.out()));
  option_database_.use_for(snes_);
  SNEDE_PETSC(SNESSetOptionsPrefix(snes_, prefix));  // also creates the KSP
  KSP inner = nullptr;
  SNEDE_PETSC(SNESGetKSP(snes_, &inner));
  option_database_.use_for(inner);
  SNESLineSearch line_search = nullptr;
  SNEDE_PETSC(SNESGetLineSearch(snes_, &line_search));
  option_database_.use_for(line_search);
  SNEDE_PETSC(SNESSetApplicationContext(snes_, this));
  SNEDE_PETSC(SNESSetFunction(snes_, residual_, residual_callback, this));
  SNEDE_PETSC(SNESSetObjective(snes_, objective_callback, this));
  SNEDE_PETSC(SNESSetTolerances(snes_, 0.0, 0.0, 0.0, options_.max_iterations, -1));
  convergence_.install(snes_);
  // Nonlinear CG's line searches take K(x)d from the Jacobian too (line_search.cpp).
  SNEDE_PETSC(SNESSetJacobian(snes_, problem_.tangent(), preconditioner_.matrix(), jacobian_callback, this));
  if (options_.method == StaticMethod::nonlinear_cg) {
    SNEDE_PETSC(SNESSetType(snes_, SNESNCG));
    SNEDE_PETSC(SNESNCGSetType(snes_, SNES_NCG_PRP));
    // The secant line search of §4.4.2 is scale-free; PETSc's cp (the scale-dependent
    // secant) needs -snes_linesearch_damping set to the problem's step scale.
    SNEDE_PETSC(SNESLineSearchSetType(line_search, "snede_secant"));
  } else {
    SNEDE_PETSC(SNESSetType(snes_, SNESNEWTONLS));
    SNEDE_PETSC(KSPSetType(inner, KSPCG));
    preconditioner_.configure(pc());
    choose_forcing(snes_, option_database_, options_.options_prefix,
                   preconditioner_.needs_matrix() || preconditioner_.has_levels(), preconditioner_.keeps_galerkin_levels());
    SNEDE_PETSC(SNESSetMaxLinearSolveFailures(snes_, options_.max_iterations));
    SNEDE_PETSC(SNESLineSearchSetPreCheck(line_search, descent_direction_callback, this));
  }
  // A line search's absolute tolerance depends on the units (cp declares CONVERGED_FNORM_ABS
  // once the slope F·y falls below it, and F is in scaled units here): convergence is decided
  // by snede's own criterion alone.
  SNEDE_PETSC(SNESLineSearchSetTolerances(line_search, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, 0.0, PETSC_DEFAULT,
                                          PETSC_DEFAULT));
  SNEDE_PETSC(SNESSetFromOptions(snes_));
  option_database_.mark_read_options_used();
  // PETSc takes any damping; a NaN one made its backtracking line search loop for ever.
  PetscReal damping = 0;
  SNEDE_PETSC(SNESLineSearchGetDamping(line_search, &damping));
  if (!(std::isfinite(damping) && damping > 0))
    throw std::invalid_argument("-" + options_.options_prefix + "snes_linesearch_damping must be positive and finite, got " +
                                std::to_string(damping));
}

void StaticSolver::follow_mesh_changes() {
  // A needle's refinement grows a mesh of a few hundred cells, where "auto" chose no
  // preconditioner, past the size where multigrid pays (and collapses or removed pieces may
  // shrink one): choose again, with solver objects made afresh for the new choice (the old ones
  // left to any handle that holds them).
  if (preconditioner_.wants_other_type()) {
    preconditioner_.choose_type_again();
    leave_solver_objects();
    ksp_.reset();
    snes_.reset();
    create_objects();
    return;
  }
  const bool resized = generation_ != problem_.generation();
  if (preconditioner_.follow_changes(resized, system_scale_, pc())) reset_objects(resized);
}

void StaticSolver::reset_objects(bool resized) {
  generation_ = problem_.generation();
  if (resized) SNEDE_PETSC(VecDuplicate(problem_.state(), residual_.out()));
  if (ksp_) {
    SNEDE_PETSC(KSPReset(ksp_));
    SNEDE_PETSC(KSPSetOperators(ksp_, problem_.tangent(), preconditioner_.matrix()));
  } else {
    SNEDE_PETSC(SNESReset(snes_));
    // SNESReset keeps the SNES's DM, whose global vector still has the old size (NCG
    // duplicates it): a fresh shell DM, then the callbacks it carries set again.
    DmHandle dm;
    SNEDE_PETSC(DMShellCreate(problem_.comm(), dm.out()));
    SNEDE_PETSC(DMShellSetGlobalVector(dm, residual_));
    SNEDE_PETSC(SNESSetDM(snes_, dm));  // the SNES holds its own reference
    SNEDE_PETSC(SNESSetObjective(snes_, objective_callback, this));
    SNEDE_PETSC(SNESSetFunction(snes_, residual_, residual_callback, this));
    SNEDE_PETSC(SNESSetJacobian(snes_, problem_.tangent(), preconditioner_.matrix(), jacobian_callback, this));
  }
  option_database_.renew_initial_guess(ksp());
  preconditioner_.configure_after_reset(pc());
}

Model& StaticSolver::model() {
  if (!model_) throw std::logic_error("StaticSolver::model(): this solver's problem is distributed, not a Model");
  return *model_;
}

SolveResult StaticSolver::solve() {
  const ExclusiveUse::Claim claim = problem_.exclusive_use().claim("a static solve");
  // A piece with rigid motions has no unique static solution: refused before any set-up, as no
  // method or preconditioner would converge (Newton spun to its iteration limit).
  {
    static const PetscLogEvent event = log_event("SnedePieceCheck");
    ScopedEvent logged(event);
    if (piece_holding_) piece_holding_->require_held(model_->constraints());
  }
  const double follow_start = wall_seconds();
  {
    static const PetscLogEvent event = log_event("SnedeFollowMesh");
    ScopedEvent logged(event);
    follow_mesh_changes();
  }
  follow_seconds_ = wall_seconds() - follow_start;
  // Linear CG divides its right-hand side and operator by the system scale, SNES its function,
  // objective (energy) and tangent; the iterate keeps its units.
  system_scale_ = convergence_.start(options_.stopping);
  problem_.enforce_constraints(problem_.state());
  SolveResult result;
  const double start = wall_seconds();
  const double start_flops = logged_flops();
  // A start that is not finite makes linear CG's right-hand side NaN: CG stops at once
  // (DIVERGED_NANORINF) and finish() reports the state.
  problem_.residual(problem_.state(), residual_);
  result.initial_residual_norm = vec_norm(residual_);
  convergence_.anchor(result.initial_residual_norm, /*fixed_reactions=*/ksp_ != nullptr);
  if (ksp_) solve_linear(result);
  else solve_nonlinear(result);
  finish(result, start, start_flops);
  preconditioner_.end_newton_solve(result.converged);
  if (result.converged) preconditioner_.remember_smoother_bounds(pc());
  option_database_.mark_read_options_used();  // a solve reads more (-snes_view, -ksp_converged_reason)
  return result;
}

void StaticSolver::solve_linear(SolveResult& result) {
  Vec u = problem_.state();
  VecHandle rhs, step;
  SNEDE_PETSC(VecDuplicate(u, rhs.out()));
  SNEDE_PETSC(VecDuplicate(u, step.out()));
  // One Newton step of the quadratic problem: J δ = −F(u), solved by CG (§3.1).
  problem_.set_linearization_point(u);
  SNEDE_PETSC(VecCopy(residual_, rhs));
  SNEDE_PETSC(VecScale(rhs, -1.0 / system_scale_));
  SNEDE_PETSC(VecSet(step, 0.0));
  const ScaledOperator scaled(problem_, system_scale_);
  // Linear CG solves linear elasticity, whose tangent does not depend on the state: what was
  // filled for an earlier solve of the same system is the same matrix.
  if (!preconditioner_.filled_for(system_scale_)) preconditioner_.fill(u, system_scale_);
  solve_through(ksp_, [&] { SNEDE_PETSC(KSPSolve(ksp_, rhs, step)); });
  // Onto the allowed motions (6.7), as Newton's steps (truncated_newton.hpp): CG's
  // iterate under a preconditioner that is not projected leaves sliding vertices' lines.
  problem_.project_onto_allowed_motions(step);
  SNEDE_PETSC(VecAXPY(u, 1.0, step));
  KSPConvergedReason reason;
  PetscInt iterations = 0;
  SNEDE_PETSC(KSPGetConvergedReason(ksp_, &reason));
  SNEDE_PETSC(KSPGetIterationNumber(ksp_, &iterations));
  result.iterations = static_cast<int>(iterations);
  result.reason = std::string(KSPConvergedReasons[reason]);
  result.converged = reason > 0;
}

void StaticSolver::solve_nonlinear(SolveResult& result) {
  Vec u = problem_.state();
  SNESConvergedReason reason;
  PetscInt iterations = 0, linear = 0;
  const ScaledOperator scaled(problem_, system_scale_);
  const bool keeps_levels = preconditioner_.begin_newton_solve();
  if (options_.method == StaticMethod::newton)
    choose_forcing(snes_, option_database_, options_.options_prefix,
                   preconditioner_.needs_matrix() || preconditioner_.has_levels(), keeps_levels);
  if (keeps_levels) {
    if (preconditioner_.structures_outlived()) {
      preconditioner_.make_structures(system_scale_);
      reset_objects(false);
    }
    SNEDE_PETSC(SNESSetLagPreconditioner(snes_, preconditioner_.lag_for_solve(system_scale_, pc())));
  }
  run_snes(reason, iterations, linear);
  if (is_line_search_newton(snes_) && (reason == SNES_DIVERGED_LINE_SEARCH || reason == SNES_DIVERGED_LOCAL_MIN))
    finish_with_full_steps(snes_, u, options_.max_iterations, iterations, reason,
                           [&] { run_snes(reason, iterations, linear); });
  result.iterations = static_cast<int>(iterations);
  result.linear_iterations = static_cast<int>(linear);
  result.reason = std::string(SNESConvergedReasons[reason]);
  result.converged = reason > 0;
}

void StaticSolver::run_snes(SNESConvergedReason& reason, PetscInt& iterations, PetscInt& linear) {
  solve_through(ksp(), [&] { SNEDE_PETSC(SNESSolve(snes_, nullptr, problem_.state())); });
  PetscInt its = 0, lits = 0;
  SNEDE_PETSC(SNESGetConvergedReason(snes_, &reason));
  SNEDE_PETSC(SNESGetIterationNumber(snes_, &its));
  SNEDE_PETSC(SNESGetLinearSolveIterations(snes_, &lits));
  iterations += its;
  linear += lits;
  preconditioner_.record_last_linear_solve(ksp());  // pending only with levels kept through the solve
}

void StaticSolver::finish(SolveResult& result, double start_seconds, double start_flops) {
  Vec u = problem_.state();
  // The verdict is checked on the final state, whatever PETSc said (§ "results, not crashes").
  const std::string inadmissible = problem_.inadmissible(u);
  const ResidualCheck check = problem_.residual(u, residual_);
  result.residual_norm = vec_norm(residual_);
  result.tolerance = convergence_.tolerance();
  judge_final_state(result, inadmissible, check.finite, check.inverted);
  result.energy = problem_.energy(u);
  result.residual_history = convergence_.history();
  result.seconds = wall_seconds() - start_seconds;
  result.flops = logged_flops() - start_flops;
}

PetscErrorCode StaticSolver::residual_callback(SNES snes, Vec x, Vec F, void* context) {
  return petsc_callback("snede static residual", [&] {
    auto* self = &callback_owner<StaticSolver>(context, "StaticSolver");
    const ResidualCheck check = self->problem_.residual(x, F);
    SNEDE_PETSC(VecScale(F, 1.0 / self->system_scale_));
    // Every rank of a distributed problem gets the same verdict, so line searches shorten the
    // same step everywhere.
    if (!check.admissible()) SNEDE_PETSC(SNESSetFunctionDomainError(snes));
  });
}

PetscErrorCode StaticSolver::objective_callback(SNES snes, Vec x, PetscReal* value, void* context) {
  return petsc_callback("snede static objective", [&] {
    auto* self = &callback_owner<StaticSolver>(context, "StaticSolver");
    // +∞ for an inverted element of a material that forbids it; NaN for a non-finite element.
    *value = self->problem_.energy(x) / self->system_scale_;
    if (std::isnan(*value)) {
      *value = std::numeric_limits<double>::infinity();
      SNEDE_PETSC(SNESSetFunctionDomainError(snes));
    }
  });
}

PetscErrorCode StaticSolver::jacobian_callback(SNES snes, Vec x, Mat J, Mat P, void* context) {
  return petsc_callback("snede static jacobian", [&] {
    StaticSolver& self = callback_owner<StaticSolver>(context, "StaticSolver");
    self.problem_.set_linearization_point(x);
    SNEDE_PETSC(MatAssemblyBegin(J, MAT_FINAL_ASSEMBLY));
    SNEDE_PETSC(MatAssemblyEnd(J, MAT_FINAL_ASSEMBLY));
    if (P != J || self.preconditioner_.has_levels())
      self.preconditioner_.refill_for_newton(snes, x, self.system_scale_, self.ksp());
  });
}

PetscErrorCode StaticSolver::descent_direction_callback(SNESLineSearch line_search, Vec /*u*/, Vec step,
                                                        PetscBool* changed, void* context) {
  return petsc_callback("snede Newton direction", [&] {
    StaticSolver& self = callback_owner<StaticSolver>(context, "StaticSolver");
    make_descent_direction(line_search, step, self.problem_, self.preconditioner_.multigrid());
    *changed = PETSC_TRUE;
  });
}

}  // namespace snede
