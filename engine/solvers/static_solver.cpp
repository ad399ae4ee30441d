#include "solvers/static_solver.hpp"

#include <petscdmshell.h>
#include <petsctime.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log_event.hpp"
#include "core/norms.hpp"
#include "core/petsc_util.hpp"
#include "core/rank_agreement.hpp"
#include "multigrid/aggregation_multigrid.hpp"
#include "multigrid/bisection_multigrid.hpp"
#include "problem/distributed_static.hpp"
#include "solvers/failed_solve.hpp"
#include "multigrid/grid_multigrid.hpp"
#include "multigrid/rank_aggregation_multigrid.hpp"
#include "problem/tangent_assembly.hpp"

namespace snede {
namespace {

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

bool is_linear(const Material& material) { return std::holds_alternative<LinearElastic>(material); }

// Whether a hierarchy's coarsest level is small enough for its direct solve: at most a
// sixteenth of the fine level (in cells or in unknowns), about as large as the grid levels'
// (4 vertex spacings wide: a 64th of the vertices, with up to d unknowns per node copy), or a
// thousand.
bool small_coarsest_level(std::size_t coarsest, std::size_t fine) {
  return coarsest <= std::max<std::size_t>(1000, fine / 16);
}

// Newton with a line search (snede's default), not a trust region (-snes_type newtontr), which
// has no line search to finish with and rejects steps without a stall.
bool is_line_search_newton(SNES snes) {
  PetscBool same = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(snes), SNESNEWTONLS, &same));
  return same;
}

// After a line-search failure Newton tries at most this many full steps, and keeps them only
// if they meet the stopping criterion (quadratic convergence needs a handful).
constexpr PetscInt newton_finish_steps = 10;
// ‖F‖ changed by less than this fraction over a Newton iteration: a stalled line search.
constexpr double newton_stall = 1e-6;

// Whether "mg" has levels for the problem: serially on any mesh; on ranks on volume meshes only
// (rank_aggregation.hpp aggregates no membrane).
bool has_multigrid(const Problem& problem) {
  const auto* distributed = dynamic_cast<const DistributedStatic*>(&problem);
  return !distributed || distributed->part().local->cell_dim() == problem.dim();
}

// "auto": multigrid from options.multigrid_from_cells (static_options.hpp), never for nonlinear CG.
std::string automatic_preconditioner(const Problem& problem, const StaticOptions& options) {
  if (options.method == StaticMethod::nonlinear_cg || problem.n_global_cells() < options.multigrid_from_cells ||
      !has_multigrid(problem))
    return PCNONE;
  return PCMG;
}

// GAMG keeps its interpolation when the matrix changes (PETSc 3.18's default), and with it the
// bounds its Chebyshev smoothers took from the first set-up's smoothed-aggregation estimate.
// Newton refills the matrix at every iteration, and a tangent that stiffened past those bounds
// made the V-cycle indefinite (DIVERGED_INDEFINITE_PC, then DIVERGED_LINE_SEARCH: a neo-Hookean
// cantilever of 30 × 6 × 6 cubes, a box with vertices sliding along oblique lines; issue 48
// item 8). The smoothers estimate their own bounds instead, again whenever their operator
// changes (-<prefix>pc_gamg_use_sa_esteig, read afterwards, overrides).
void configure_gamg(PC pc, const std::string& pc_type) {
  if (pc_type == PCGAMG) SNEDE_PETSC(PCGAMGSetUseSAEstEig(pc, PETSC_FALSE));
}

// KSPReset and SNESReset keep a KSP's initial-guess object (-<prefix>ksp_guess_type fischer or
// pod) with the vectors of the mesh before a change: the first solve after a needle's
// refinement failed with PETSc error 75 ("Incompatible vector local lengths"). An empty guess of
// the same type, read from the solver's options again, replaces it.
void renew_initial_guess(KSP ksp, const SolverOptions& options) {
  const char* prefix = nullptr;
  SNEDE_PETSC(KSPGetOptionsPrefix(ksp, &prefix));
  // KSPGetGuess would give a KSP without one an empty guess, which KSPSolve then consults.
  if (!options.string_option(std::string(prefix ? prefix : "") + "ksp_guess_type")) return;
  KSPGuess kept = nullptr;
  SNEDE_PETSC(KSPGetGuess(ksp, &kept));
  KSPGuessType type = nullptr;
  SNEDE_PETSC(KSPGuessGetType(kept, &type));
  if (!type) return;
  const std::string kept_type = type;
  KSPGuess fresh = nullptr;
  SNEDE_PETSC(KSPGuessCreate(PetscObjectComm(reinterpret_cast<PetscObject>(ksp)), &fresh));
  options.use_for(fresh);
  SNEDE_PETSC(PetscObjectSetOptionsPrefix(reinterpret_cast<PetscObject>(fresh), prefix));
  SNEDE_PETSC(KSPGuessSetType(fresh, kept_type.c_str()));
  SNEDE_PETSC(KSPGuessSetFromOptions(fresh));
  SNEDE_PETSC(KSPSetGuess(ksp, fresh));  // the KSP holds its own reference
  SNEDE_PETSC(KSPGuessDestroy(&fresh));
}

Model* serial_model(Problem& problem) {
  auto* serial = dynamic_cast<ModelProblem*>(&problem);
  return serial ? &serial->model() : nullptr;
}

// Every rank must solve with the same options: a rank with another method or tolerance would
// wait in a collective call the others never make.
void require_same_options_everywhere(MPI_Comm comm, const StaticOptions& options) {
  InputDigest petsc_options;
  for (const auto& [name, value] : options.petsc_options) petsc_options.add(name).add(value);
  RankAgreement("StaticSolver")
      .input("method", static_cast<double>(options.method))
      .input("criterion", static_cast<double>(options.stopping.criterion))
      .input("rtol", options.stopping.rtol)
      .input("round_tolerance", options.stopping.round_tolerance)
      .input("max_iterations", options.max_iterations)
      .input("options_prefix", options.options_prefix)
      .input("preconditioner", options.preconditioner)
      .input("petsc_options", petsc_options)
      .require(comm);
}

}  // namespace

StaticSolver::StaticSolver(Model& model, StaticOptions options, const RefinementHierarchy* hierarchy)
    : StaticSolver(std::make_unique<ModelProblem>(model), nullptr, std::move(options), hierarchy) {}

StaticSolver::StaticSolver(Problem& problem, StaticOptions options)
    : StaticSolver(nullptr, &problem, std::move(options), nullptr) {}

StaticSolver::StaticSolver(std::unique_ptr<ModelProblem> owned, Problem* problem, StaticOptions options,
                           const RefinementHierarchy* hierarchy)
    : owned_problem_(std::move(owned)),
      problem_(problem ? *problem : *owned_problem_),
      model_(serial_model(problem_)),
      options_(std::move(options)),
      option_database_(options_.options_prefix, options_.petsc_options),
      hierarchy_(hierarchy),
      reuse_(number_option("mg_refresh_ratio", PreconditionerReuse::default_refresh_ratio)),
      rebuild_after_edits_(option_database_.bool_option(options_.options_prefix + "rebuild_after_edits", false)) {
  require_same_options_everywhere(problem_.comm(), options_);
  if (model_) {
    // The reference (-static_rebuild_after_edits) labels the pieces from scratch after each edit too.
    if (rebuild_after_edits_) piece_holding_.emplace(model_->body().mesh());
    else piece_holding_.emplace(model_->body().mesh(), PieceHolding::FollowEdits{});
  }
  if (options_.stopping.rtol <= 0 || !std::isfinite(options_.stopping.rtol))
    throw std::invalid_argument("rtol must be positive, got " + std::to_string(options_.stopping.rtol));
  if (!(options_.stopping.round_tolerance >= 0) || !std::isfinite(options_.stopping.round_tolerance))
    throw std::invalid_argument("round_tolerance must be finite and non-negative, got " +
                                std::to_string(options_.stopping.round_tolerance));
  if (options_.stopping.criterion == StoppingCriterion::relative && !(options_.stopping.rtol < 1))
    throw std::invalid_argument("a relative rtol must be below 1, got " + std::to_string(options_.stopping.rtol));
  if (options_.max_iterations < 1)
    throw std::invalid_argument("max_iterations must be at least 1, got " + std::to_string(options_.max_iterations));
  if (options_.method == StaticMethod::linear_cg && !is_linear(problem_.material()))
    throw std::invalid_argument(
        "method 'cg' (linear CG) solves the linear problem and needs LinearElastic; use 'ncg' or 'newton' for "
        "nonlinear materials");
  // The command line (copied into the solver's database) wins over the argument.
  pc_type_ = option_database_.string_option(options_.options_prefix + "pc_type")
                 .value_or(options_.preconditioner.empty() ? std::string("auto") : options_.preconditioner);
  if (pc_type_ == "auto") {
    automatic_ = true;
    pc_type_ = automatic_preconditioner(problem_, options_);
    // -<prefix>pc_type auto is snede's: PETSc, which reads the option again, must see the choice.
    if (option_database_.string_option(options_.options_prefix + "pc_type"))
      option_database_.set_string_option(options_.options_prefix + "pc_type", pc_type_);
  }
  if (options_.method == StaticMethod::nonlinear_cg && pc_type_ != PCNONE)
    throw std::invalid_argument("a preconditioner ('" + pc_type_ + "') applies to the CG of methods 'cg' and 'newton'; "
                                "nonlinear CG ('ncg') takes no preconditioner");
  if (pc_type_ != PCMG && !automatic_ && option_database_.string_option(options_.options_prefix + "mg_refresh_ratio"))
    throw std::invalid_argument("-" + options_.options_prefix + "mg_refresh_ratio applies to the preconditioner 'mg'; "
                                "this solver's is '" + pc_type_ + "'");
  PetscMPIInt ranks = 1;
  SNEDE_PETSC(MPI_Comm_size(problem_.comm(), &ranks));
  // PETSc's incomplete factorisations are sequential: PETSc's own error names no remedy.
  if (ranks > 1 && (pc_type_ == PCILU || pc_type_ == PCICC))
    throw std::invalid_argument("preconditioner '" + pc_type_ + "' factors a whole matrix on one process; on " +
                                std::to_string(ranks) + " MPI ranks use 'bjacobi' (" + pc_type_ +
                                " of each rank's block: -" + options_.options_prefix + "sub_pc_type " + pc_type_ +
                                "), 'mg' or 'gamg'");
  // Jacobi reads the shell's diagonal (MatGetDiagonal), mg builds its own levels (and needs
  // entries only for Galerkin levels); every other PC needs entries.
  pc_needs_matrix_ = pc_type_ != PCNONE && pc_type_ != PCJACOBI && pc_type_ != PCMG;
  needs_matrix_ = pc_needs_matrix_;
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
    SNESSetConvergenceTest(snes_, snes_converged_callback, nullptr, nullptr);
    SNESLineSearch line_search = nullptr;
    SNESGetLineSearch(snes_, &line_search);
    SNESLineSearchSetPreCheck(
        line_search, [](SNESLineSearch, Vec, Vec, PetscBool*, void*) { return orphaned_callback_error(owner); }, nullptr);
  }
  if (ksp_) KSPSetConvergenceTest(ksp_, ksp_converged_callback, nullptr, nullptr);
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

void StaticSolver::create_objects() {
  generation_ = problem_.generation();
  if (!multigrid_) build_multigrid();  // before the operators: Galerkin levels need the assembled tangent
  SNEDE_PETSC(VecDuplicate(problem_.state(), residual_.out()));
  const char* prefix = options_.options_prefix.c_str();
  if (options_.method == StaticMethod::linear_cg) {
    SNEDE_PETSC(KSPCreate(problem_.comm(), ksp_.out()));
    option_database_.use_for(ksp_);
    SNEDE_PETSC(KSPSetOptionsPrefix(ksp_, prefix));
    SNEDE_PETSC(KSPSetType(ksp_, KSPCG));
    PC pc = nullptr;
    SNEDE_PETSC(KSPGetPC(ksp_, &pc));
    option_database_.use_for(pc);
    SNEDE_PETSC(PCSetType(pc, pc_type_.c_str()));
    configure_gamg(pc, pc_type_);
    SNEDE_PETSC(PCSetUseAmat(pc, PETSC_FALSE));  // see the Newton branch
    if (multigrid_) configure_multigrid(pc);
    SNEDE_PETSC(KSPSetOperators(ksp_, problem_.tangent(), preconditioning_matrix()));
    SNEDE_PETSC(KSPSetTolerances(ksp_, 0.0, 0.0, PETSC_DEFAULT, options_.max_iterations));
    SNEDE_PETSC(KSPSetConvergenceTest(ksp_, ksp_converged_callback, this, nullptr));
    // The criterion is on the equilibrium residual b − Jδ itself: with a preconditioner CG
    // would otherwise hand the test the preconditioned norm ‖B(b − Jδ)‖. Without one the
    // natural norm √(r·r) is that norm, from the dot product CG takes anyway: no VecNorm per
    // iteration (a tenth of a small solve, the 2D needle's, issue 33).
    SNEDE_PETSC(KSPSetNormType(ksp_, pc_type_ == PCNONE ? KSP_NORM_NATURAL : KSP_NORM_UNPRECONDITIONED));
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
  SNEDE_PETSC(SNESSetConvergenceTest(snes_, snes_converged_callback, this, nullptr));
  // Nonlinear CG's line searches take K(x)d from the Jacobian too (line_search.cpp).
  SNEDE_PETSC(SNESSetJacobian(snes_, problem_.tangent(), preconditioning_matrix(), jacobian_callback, this));
  if (options_.method == StaticMethod::nonlinear_cg) {
    SNEDE_PETSC(SNESSetType(snes_, SNESNCG));
    SNEDE_PETSC(SNESNCGSetType(snes_, SNES_NCG_PRP));
    // The secant line search of §4.4.2 is scale-free; PETSc's cp (the scale-dependent
    // secant) needs -snes_linesearch_damping set to the problem's step scale.
    SNEDE_PETSC(SNESLineSearchSetType(line_search, "snede_secant"));
  } else {
    SNEDE_PETSC(SNESSetType(snes_, SNESNEWTONLS));
    SNEDE_PETSC(KSPSetType(inner, KSPCG));
    PC pc = nullptr;
    SNEDE_PETSC(KSPGetPC(inner, &pc));
    option_database_.use_for(pc);
    SNEDE_PETSC(PCSetType(pc, pc_type_.c_str()));
    configure_gamg(pc, pc_type_);
    // A multigrid PC smooths its finest level with the assembled matrix, not the shell (each
    // shell product costs several assembled ones); -<prefix>pc_use_amat turns it back.
    SNEDE_PETSC(PCSetUseAmat(pc, PETSC_FALSE));
    if (multigrid_) configure_multigrid(pc);
    choose_forcing(needs_matrix_ || multigrid_);
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

void StaticSolver::choose_forcing(bool preconditioned) {
  // A forcing the user chose is left alone.
  if (option_database_.string_option(options_.options_prefix + "snes_ksp_ew") ||
      option_database_.string_option(options_.options_prefix + "ksp_rtol"))
    return;
  KSP inner = nullptr;
  SNEDE_PETSC(SNESGetKSP(snes_, &inner));
  // Truncated Newton (§2.4.3) without a PC: the inner CG stops early (Eisenstat–Walker),
  // tightening as the outer converges, and where the tangent is indefinite (far from the
  // solution of a soft body) CG stops at the negative curvature and its iterate so far is used
  // as the search direction.
  SNEDE_PETSC(SNESKSPSetUseEW(snes_, preconditioned ? PETSC_FALSE : PETSC_TRUE));
  if (!preconditioned) return;
  // With a PC set up anew at every Newton iteration (GAMG on an assembled tangent, matrix-free
  // bisection levels), a few accurate Newton steps cost less than many truncated ones: at
  // 98 304 neo-Hookean tetrahedra 9 iterations (inner rtol 1e-3) against 37–44 with
  // Eisenstat-Walker. Galerkin levels kept through the solve cost nothing per iteration: there
  // 1e-2 took as many Newton iterations and a quarter fewer flops in the cut loops, and the same
  // on the static block (issue 49; docs/results/interactive.md). Eisenstat–Walker took half the
  // CG in the loops but four times the Newton iterations on the static block.
  const double inner_rtol = keeps_galerkin_levels() ? kept_levels_inner_rtol : set_up_levels_inner_rtol;
  SNEDE_PETSC(KSPSetTolerances(inner, inner_rtol, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT));
}

void StaticSolver::follow_mesh_changes() {
  // A needle's refinement grows a mesh of a few hundred cells, where "auto" chose no
  // preconditioner, past the size where multigrid pays (and collapses or removed pieces may
  // shrink one): choose again, with solver objects made afresh for the new choice.
  if (automatic_ && automatic_preconditioner(problem_, options_) != pc_type_) {
    choose_preconditioner_again();
    return;
  }
  const bool resized = generation_ != problem_.generation();
  const bool stale_matrix = needs_matrix_ && (!assembled_ || !assembled_->matches());
  const bool stale_multigrid = multigrid_ && !levels_match();
  if (!resized && !stale_matrix && !stale_multigrid) return;
  if (!resized && !stale_matrix && levels_match_mesh()) {
    // Only the constraints changed (a needle's stick-slip): a change of a few vertices. Galerkin
    // levels that Newton keeps across solves keep their interpolation, made for the earlier
    // constraints, and are refilled at the next solve (fine matrix and Galerkin products, no new
    // grid or structure); Newton's step is projected onto the allowed motions. They take the
    // constraints over once they show their age (solve_nonlinear).
    if (lags_constraint_changes()) return;
    take_over_constraints();
    return;
  }
  if (!resized && carry_levels_over_moved_vertices()) return;
  make_structures_for_mesh(resized);
}

bool StaticSolver::tangent_follows_edits() {
  // The sparsity follows the edit: the rows of the vertices it touched are made again, the others
  // copied. Where the tangent does not depend on the state (problem.hpp) and Newton keeps its
  // levels, the values do too: the blocks an edit did not touch keep their values exactly and only
  // those it did (a cut's few hundred, of 10⁵) are computed, instead of every element's matrix
  // (11–30 ms at 20–25k tetrahedra against 3–5). Elsewhere the kept blocks would be of the earlier
  // fill's state: measured on the cut loops (docs/results/interactive.md), the older
  // preconditioner cost more CG than the assembly saved.
  if (!assembled_ || rebuild_after_edits_) return false;
  static const PetscLogEvent event = log_event("SnedeTangentSparsity");
  ScopedEvent logged(event);
  // In the scale of the last solve's system, which the earlier tangent was filled in.
  const ScaledOperator scaled(problem_, system_scale_);
  std::unique_ptr<AssembledProblemTangent> edited =
      assembled_->follow_edits(lags_constraint_changes() ? problem_.state() : nullptr);
  if (!edited) return false;
  assembled_ = std::move(edited);
  ++sparsity_builds_;
  ++sparsity_edits_;
  preconditioner_filled_ = false;  // the PC is made for the new matrix
  tangent_follows_edits_ = assembled_->filled();
  tangent_edited_at_scale_ = system_scale_;
  return true;
}

bool StaticSolver::carry_levels_over_moved_vertices() {
  // A cut's snap moves a vertex or two onto the blade and changes no element (half of a
  // scalpel's moves, issue 49): Galerkin levels that Newton keeps across solves keep serving,
  // with the tangent of the earlier shapes, until they show their age; then solve_nonlinear
  // makes them anew for the shapes of now. The operator of every solve is the exact tangent.
  if (rebuild_after_edits_ || !model_ || !assembled_ || !multigrid_ || !lags_constraint_changes()) return false;
  if (!multigrid_->carry_over_moved_vertices(*model_)) return false;
  if (!assembled_->follow_moved_vertices()) throw std::logic_error("levels carried over a change of elements");
  return true;
}

void StaticSolver::make_structures_for_mesh(bool resized) {
  generation_ = problem_.generation();
  if (resized) SNEDE_PETSC(VecDuplicate(problem_.state(), residual_.out()));
  // A flip or a cut changes the sparsity; vertices moved alone (a cut's snap) keep it, and the
  // values are filled again for the new reference shapes.
  if (assembled_ && !rebuild_after_edits_ && assembled_->follow_moved_vertices())
    preconditioner_filled_ = false;
  else if (!tangent_follows_edits())
    assembled_.reset();
  const std::unique_ptr<Multigrid> earlier = std::move(multigrid_);
  build_multigrid(earlier.get());
  if (ksp_) {
    SNEDE_PETSC(KSPReset(ksp_));
    SNEDE_PETSC(KSPSetOperators(ksp_, problem_.tangent(), preconditioning_matrix()));
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
    SNEDE_PETSC(SNESSetJacobian(snes_, problem_.tangent(), preconditioning_matrix(), jacobian_callback, this));
  }
  renew_initial_guess(ksp(), option_database_);
  if (needs_matrix_ || pc_type_ == PCMG) {
    // A reset PCGAMG keeps its levels' sizes ("Cannot change local size of Amat after use"):
    // a fresh implementation of the same type, configured from the options again.
    PC pc = nullptr;
    SNEDE_PETSC(KSPGetPC(ksp(), &pc));
    SNEDE_PETSC(PCSetType(pc, PCNONE));
    SNEDE_PETSC(PCSetType(pc, pc_type_.c_str()));
    configure_gamg(pc, pc_type_);
    if (multigrid_) configure_multigrid(pc);
    SNEDE_PETSC(PCSetFromOptions(pc));
  }
}

MatrixFormat StaticSolver::assembled_tangent_format() const {
  // GAMG works on AIJ, Galerkin levels on what their products read.
  return pc_needs_matrix_ || !multigrid_ ? MatrixFormat::aij : multigrid_->assembled_tangent_format();
}

Mat StaticSolver::preconditioning_matrix() {
  if (!needs_matrix_) return problem_.tangent();
  // Levels of another kind (bisection, then grid after a cut) may read another format.
  if (assembled_ && assembled_format_ != assembled_tangent_format()) assembled_.reset();
  if (!assembled_) {
    static const PetscLogEvent event = log_event("SnedeTangentSparsity");
    ScopedEvent logged(event);
    // A membrane's compressed elements must not make the PC indefinite (tangent_assembly.hpp).
    assembled_format_ = assembled_tangent_format();
    assembled_ = problem_.make_assembled_tangent(assembled_format_);
    ++sparsity_builds_;
    preconditioner_filled_ = false;
    tangent_follows_edits_ = false;  // a new tangent is assembled
  }
  return assembled_->mat();
}

void StaticSolver::build_multigrid(Multigrid* earlier) {
  if (pc_type_ != PCMG) return;
  const std::string prefix = "-" + options_.options_prefix;
  const std::optional<std::string> galerkin = option_database_.string_option(options_.options_prefix + "pc_mg_galerkin");
  if (galerkin && *galerkin != "none" && *galerkin != "false" && *galerkin != "0")
    throw std::invalid_argument(prefix + "pc_mg_galerkin: 'mg' chooses its coarse operators itself (the levels' "
                                "own shells on a bisection hierarchy, Galerkin products on grid or aggregation levels)");
  // PCMG's own -pc_mg_levels would replace the levels configured here: it limits them instead.
  const std::optional<std::string> levels = option_database_.string_option(options_.options_prefix + "pc_mg_levels");
  int max_levels = 0;
  if (levels) {
    try {
      std::size_t used = 0;
      max_levels = std::stoi(*levels, &used);
      if (used != levels->size()) throw std::invalid_argument(*levels);
    } catch (const std::exception&) {
      throw std::invalid_argument(prefix + "pc_mg_levels must be an integer, got '" + *levels + "'");
    }
    if (max_levels < 2)
      throw std::invalid_argument("mg needs at least 2 levels (the mesh and a coarser one), got " + prefix +
                                  "pc_mg_levels " + *levels);
  }
  const std::string coarsening =
      option_database_.string_option(options_.options_prefix + "mg_coarsening").value_or("auto");
  if (coarsening != "auto" && coarsening != "bisection" && coarsening != "aggregation" && coarsening != "grid")
    throw std::invalid_argument(prefix + "mg_coarsening must be auto, bisection, aggregation or grid, got '" +
                                coarsening + "'");
  if (coarsening == "bisection" && !hierarchy_)
    throw std::invalid_argument(prefix + "mg_coarsening bisection: this mesh has no bisection hierarchy (refine it "
                                "with mesh.refine_uniform or refine_around first, or use grid or aggregation)");
  multigrid_.reset();
  if (!model_) {
    build_rank_multigrid(coarsening, max_levels);
    return;
  }
  // A mesh read from a file and refined locally (along a needle) has that mesh, or more, as the
  // coarsest bisection level: a direct solve on it costs more than the grid levels (a
  // 21k-tetrahedron liver took 1.6 s per factorisation). Its roots tell before the levels are made.
  const bool small_roots =
      hierarchy_ && small_coarsest_level(hierarchy_->roots().size(), model_->body().mesh().n_cells());
  const bool refused_before = coarsening == "auto" && hierarchy_ && bisection_refused_at_splits_ == hierarchy_->n_splits();
  if (coarsening != "aggregation" && coarsening != "grid" && hierarchy_ && (small_roots || coarsening == "bisection") &&
      !refused_before) {
    try {
      static const PetscLogEvent event = log_event("SnedeBisectionLevels");
      ScopedEvent logged(event);
      multigrid_ = std::make_unique<BisectionMultigrid>(*model_, *hierarchy_, max_levels);
      const std::vector<std::size_t> unknowns = multigrid_->level_unknowns();
      if (coarsening == "auto" && !small_coarsest_level(unknowns.front(), unknowns.back())) multigrid_.reset();
    } catch (const std::invalid_argument&) {
      // No conforming coarser cut (a mesh never refined, or one that was cut or flipped since):
      // any mesh can be coarsened on its own.
      if (coarsening == "bisection") throw;
    }
    if (multigrid_) {
      bisection_refused_at_splits_.reset();
    } else {
      bisection_refused_at_splits_ = hierarchy_->n_splits();
    }
  }
  if (!multigrid_ && coarsening != "aggregation") {
    if (max_levels > 2) throw std::invalid_argument(prefix + "pc_mg_levels: grid coarsening gives 2 levels");
    static const PetscLogEvent event = log_event("SnedeGridLevels");
    ScopedEvent logged(event);
    // Volume meshes keep the grid of the first build, so that levels follow edits. A membrane's
    // gets a grid chosen for each build: on the bell of the membrane-cut scene, levels on the first
    // build's grid made Newton's line search fail after a cut (DIVERGED_LINE_SEARCH after 218
    // iterations) where a grid chosen anew converged (its positive-part tangent is sensitive to
    // the coarse space; not understood yet).
    const bool keeps_grid = !model_->body().mesh().is_surface();
    if (earlier && keeps_grid && !rebuild_after_edits_) multigrid_ = earlier->follow_edits();
    if (multigrid_) {
      ++multigrid_edits_;
    } else {
      auto grid = grid_geometry_ && keeps_grid
          ? std::make_unique<GridMultigrid>(*model_, *grid_geometry_)
          : std::make_unique<GridMultigrid>(*model_, number_option("mg_grid_width", GridMultigrid::default_grid_width));
      grid_geometry_ = grid->geometry();
      multigrid_ = std::move(grid);
    }
  }
  const bool smoothing = option_database_.bool_option(options_.options_prefix + "mg_aggregation_smoothing", false);
  if (!multigrid_)
    multigrid_ = std::make_unique<AggregationMultigrid>(
        *model_, max_levels, smoothing,
        number_option("mg_aggregate_width", AggregationMultigrid::default_aggregate_width));
  // An option for another kind of levels than those made is a mistake the user should hear of,
  // except the grid's width on bisection levels chosen by "auto": grid levels take over after
  // the first cut or flip (checked now all the same).
  const std::string source = multigrid_->source();
  const bool grid_may_follow = source == "bisection" && coarsening == "auto";
  if (grid_may_follow)
    GridMultigrid::require_valid_width(number_option("mg_grid_width", GridMultigrid::default_grid_width));
  for (const auto& [name, applies_to] : {std::pair<std::string, std::string>{"mg_aggregate_width", "aggregation"},
                                         {"mg_aggregation_smoothing", "aggregation"}, {"mg_grid_width", "grid"}})
    if (source != applies_to && !(applies_to == "grid" && grid_may_follow) &&
        option_database_.string_option(options_.options_prefix + name))
      throw std::invalid_argument(prefix + name + " applies to " + applies_to + " levels; these are " + source +
                                  " levels (-" + options_.options_prefix + "mg_coarsening chooses)");
  needs_matrix_ = pc_needs_matrix_ || multigrid_->needs_assembled_tangent();
  ++multigrid_builds_;
}

void StaticSolver::build_rank_multigrid(const std::string& coarsening, int max_levels) {
  const std::string prefix = "-" + options_.options_prefix;
  if (coarsening != "auto" && coarsening != "aggregation")
    throw std::invalid_argument(prefix + "mg_coarsening " + coarsening + ": on MPI ranks 'mg' coarsens by aggregation "
                                "of each rank's vertices (bisection and grid levels need the whole mesh)");
  for (const char* name : {"mg_grid_width", "mg_aggregation_smoothing"})
    if (option_database_.string_option(options_.options_prefix + name))
      throw std::invalid_argument(prefix + name + " does not apply on MPI ranks, whose 'mg' levels are aggregates of "
                                  "each rank's vertices");
  auto& distributed = dynamic_cast<DistributedStatic&>(problem_);
  multigrid_ = std::make_unique<RankAggregationMultigrid>(
      distributed, max_levels, number_option("mg_aggregate_width", AggregationMultigrid::default_aggregate_width));
  needs_matrix_ = true;
  ++multigrid_builds_;
}

void StaticSolver::anchor_relative_rule(double initial_norm) {
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

bool StaticSolver::levels_match() const { return !model_ || multigrid_->matches(*model_); }

bool StaticSolver::levels_match_mesh() const { return !model_ || multigrid_->matches_mesh(*model_); }

Model& StaticSolver::model() {
  if (!model_) throw std::logic_error("StaticSolver::model(): this solver's problem is distributed, not a Model");
  return *model_;
}

void StaticSolver::choose_preconditioner_again() {
  const std::string previous = pc_type_;
  pc_type_ = automatic_preconditioner(problem_, options_);
  // The levels are made before the solver's objects are replaced: an option they refuse (the
  // -<prefix>mg_ options are checked only once mg is chosen) leaves the solver as it was, and
  // the next solve refuses it again.
  needs_matrix_ = pc_needs_matrix_;  // false: the automatic choices are none and mg
  multigrid_.reset();
  try {
    build_multigrid();  // sets needs_matrix_ for Galerkin levels
  } catch (...) {
    pc_type_ = previous;
    multigrid_.reset();
    throw;
  }
  if (option_database_.string_option(options_.options_prefix + "pc_type"))
    option_database_.set_string_option(options_.options_prefix + "pc_type", pc_type_);
  assembled_.reset();
  preconditioner_filled_ = false;
  leave_solver_objects();
  ksp_.reset();
  snes_.reset();
  create_objects();
}

double StaticSolver::number_option(const std::string& name, double fallback) const {
  const std::optional<std::string> text = option_database_.string_option(options_.options_prefix + name);
  if (!text) return fallback;
  try {
    std::size_t used = 0;
    const double value = std::stod(*text, &used);
    if (used != text->size()) throw std::invalid_argument(*text);
    return value;
  } catch (const std::exception&) {
    throw std::invalid_argument("-" + options_.options_prefix + name + " must be a number, got '" + *text + "'");
  }
}

void StaticSolver::set_up_multigrid(PC pc) {
  build_multigrid();
  configure_multigrid(pc);
}

void StaticSolver::configure_multigrid(PC pc) {
  // Bounds from another number of levels do not apply.
  if (smoother_bounds_.size() + 1 != static_cast<std::size_t>(multigrid_->n_levels())) smoother_bounds_.clear();
  multigrid_->configure(pc, option_database_, smoother_bounds_);
  // The finest level smooths with the PC's matrix: the assembled tangent for Galerkin levels
  // (their products need entries), else the shell (see create_objects).
  SNEDE_PETSC(PCSetUseAmat(pc, PETSC_FALSE));
  // The levels come with their own operators and interpolations: PCMG must not coarsen the
  // SNES's shell DM (which it would try after a mesh change, when the PC gets that DM).
  SNEDE_PETSC(PCSetDM(pc, nullptr));
  preconditioner_filled_ = false;
}

void StaticSolver::remember_smoother_bounds() {
  if (!multigrid_ || !smoother_bounds_.empty()) return;
  PC pc = nullptr;
  SNEDE_PETSC(KSPGetPC(ksp(), &pc));
  PetscBool is_mg = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCMG, &is_mg));
  if (is_mg) smoother_bounds_ = chebyshev_estimates(pc);  // called after a solve: set up
}

void StaticSolver::refill_preconditioner(SNES snes, Vec x) {
  PetscInt lag = 1, iteration = 0;
  SNEDE_PETSC(SNESGetLagPreconditioner(snes, &lag));
  SNEDE_PETSC(SNESGetIterationNumber(snes, &iteration));
  // Galerkin levels kept through a solve (solve_nonlinear) are filled again at the state of now
  // when the last linear solve failed with them (kept levels made Newton's line search fail on
  // the 63k liver), or when they show their age (preconditioner_reuse.hpp: on the static 98k block
  // the CG per Newton iteration grew from 3 to 42 over 13 iterations with the levels of the
  // first). Aged levels that lag a change of constraints (a needle's stick-slip) take the
  // constraints over at the next solve instead: refilled on their earlier interpolation they keep
  // the old baseline (preconditioner_reuse.hpp), and would be refilled at every later iteration.
  if (keeps_levels_through_solve_) {
    const bool failed = record_last_linear_solve();
    if (lag == -1 && (failed || (!reuse_.keep() && levels_match()))) {
      SNEDE_PETSC(SNESSetLagPreconditioner(snes, -2));
      lag = -2;
      preconditioner_filled_ = false;
    }
    linear_solve_pending_ = true;
  }
  // As SNES decides whether to rebuild the PC: -1 never again (-2 becomes -1 once built), k > 1
  // every k-th iteration.
  const bool lagged = (lag == -1 || (lag > 1 && iteration % lag != 0)) && preconditioner_filled_;
  if (lagged) return;
  fill_preconditioner(x);
  // Levels refilled on an interpolation of earlier constraints do not set a new baseline.
  if (keeps_levels_through_solve_) reuse_.filled(levels_match());
}

bool StaticSolver::record_last_linear_solve() {
  if (!linear_solve_pending_) return false;
  linear_solve_pending_ = false;
  PetscInt iterations = 0;
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  SNEDE_PETSC(KSPGetIterationNumber(ksp(), &iterations));
  SNEDE_PETSC(KSPGetConvergedReason(ksp(), &reason));
  reuse_.record_linear_solve(static_cast<int>(iterations), reason > 0);
  return reason < 0;
}

void StaticSolver::fill_preconditioner(Vec u) {
  // A tangent made from the earlier one is filled already, unless the system's scale changed since.
  if (assembled_ && !(tangent_follows_edits_ && tangent_edited_at_scale_ == system_scale_)) {
    static const PetscLogEvent event = log_event("SnedeTangentAssembly");
    ScopedEvent logged(event);
    assembled_->assemble(u);
    ++tangent_assemblies_;
  }
  tangent_follows_edits_ = false;
  if (multigrid_) {
    static const PetscLogEvent event = log_event("SnedeLevelsUpdate");
    ScopedEvent logged(event);
    multigrid_->update(u, assembled_ ? assembled_->mat() : nullptr);
  }
  ++preconditioner_fills_;
  preconditioner_filled_ = true;
  filled_at_scale_ = system_scale_;
  filled_for_constraints_ = problem_.projection_fingerprint();
}

bool StaticSolver::filled_for_current_system() const {
  return preconditioner_filled_ && filled_at_scale_ == system_scale_ &&
         filled_for_constraints_ == problem_.projection_fingerprint();
}

bool StaticSolver::keeps_galerkin_levels() const {
  return snes_ && options_.method == StaticMethod::newton && multigrid_ && multigrid_->needs_assembled_tangent() &&
         !option_database_.string_option(options_.options_prefix + "snes_lag_preconditioner");
}

bool StaticSolver::lags_constraint_changes() const { return keeps_galerkin_levels() && reuse_.keep(); }

void StaticSolver::take_over_constraints() {
  // The same levels take the constraints over (new levels if one is no longer held), on a fresh
  // PC; the solver objects stay as they are.
  PC pc = nullptr;
  SNEDE_PETSC(KSPGetPC(ksp(), &pc));
  SNEDE_PETSC(PCSetType(pc, PCNONE));
  if (multigrid_->follow_constraints()) {
    configure_multigrid(pc);
  } else {
    set_up_multigrid(pc);
  }
  SNEDE_PETSC(PCSetFromOptions(pc));
}

double StaticSolver::current_tolerance() const {
  return rule_.tolerance(external_norm_, ksp_ ? reaction_norm_ : problem_.last_reaction_norm());
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
  history_.clear();
  external_norm_ = problem_.external_force_norm();
  // The force scale is a scan of the mesh: once per solve, not once per iteration.
  rule_ = options_.stopping;
  rule_.force_scale = problem_.force_scale();
  rule_.n_dofs = static_cast<double>(problem_.n_global_dofs());
  // Every method solves the system divided by the force scale E·t·H (E·H² in 3D), so that its
  // dot products stay in range whatever the units (E = 1e155 Pa overflows p·Ap otherwise):
  // linear CG its right-hand side and operator, SNES its function, objective (energy) and
  // tangent. The iterate keeps its units and the stopping tests multiply back.
  system_scale_ = std::isfinite(rule_.force_scale) && rule_.force_scale > 0 ? rule_.force_scale : 1.0;
  problem_.enforce_constraints(problem_.state());
  SolveResult result = ksp_ ? solve_linear() : solve_nonlinear();
  if (result.converged) remember_smoother_bounds();
  option_database_.mark_read_options_used();  // a solve reads more (-snes_view, -ksp_converged_reason)
  return result;
}

SolveResult StaticSolver::solve_linear() {
  SolveResult result;
  const double start = wall_seconds();
  const double start_flops = logged_flops();
  Vec u = problem_.state();
  VecHandle rhs, step;
  SNEDE_PETSC(VecDuplicate(u, rhs.out()));
  SNEDE_PETSC(VecDuplicate(u, step.out()));
  // A start that is not finite makes the right-hand side NaN: CG stops at once
  // (DIVERGED_NANORINF) and finish() reports the state.
  problem_.residual(u, residual_);
  reaction_norm_ = problem_.last_reaction_norm();
  result.initial_residual_norm = vec_norm(residual_);
  anchor_relative_rule(result.initial_residual_norm);
  // One Newton step of the quadratic problem: J δ = −F(u), solved by CG (§3.1).
  problem_.set_linearization_point(u);
  SNEDE_PETSC(VecCopy(residual_, rhs));
  SNEDE_PETSC(VecScale(rhs, -1.0 / system_scale_));
  SNEDE_PETSC(VecSet(step, 0.0));
  const ScaledOperator scaled(problem_, system_scale_);
  // Linear CG solves linear elasticity, whose tangent does not depend on the state: what was
  // filled for an earlier solve of the same system is the same matrix.
  if (!filled_for_current_system()) fill_preconditioner(u);
  solve_through(ksp_, [&] { SNEDE_PETSC(KSPSolve(ksp_, rhs, step)); });
  // Onto the allowed motions (6.7), as Newton's steps (descent_direction_callback): CG's
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
  finish(result, start, start_flops);
  return result;
}

SolveResult StaticSolver::solve_nonlinear() {
  SolveResult result;
  const double start = wall_seconds();
  const double start_flops = logged_flops();
  Vec u = problem_.state();
  problem_.residual(u, residual_);
  result.initial_residual_norm = vec_norm(residual_);
  anchor_relative_rule(result.initial_residual_norm);
  SNESConvergedReason reason;
  PetscInt iterations = 0, linear = 0;
  const ScaledOperator scaled(problem_, system_scale_);
  // Galerkin levels (an assembled tangent, its products with the interpolation, a coarse
  // factorisation) are filled at the first Newton iteration of a solve and kept through its other
  // iterations until they show their age (preconditioner_reuse.hpp), unless the options lag
  // otherwise: filling them at every iteration cost more than the CG iterations it saves
  // (docs/results/interactive.md). While the mesh and the projections stay the same, the next
  // solves keep them too, by the same test.
  // After a change of constraints alone (a needle's stick-slip) the levels are refilled with
  // the interpolation of the earlier constraints (follow_mesh_changes) until they show their
  // age: then they take the constraints of now over.
  keeps_levels_through_solve_ = keeps_galerkin_levels();
  if (options_.method == StaticMethod::newton) choose_forcing(needs_matrix_ || multigrid_);
  linear_solve_pending_ = false;
  if (keeps_levels_through_solve_) {
    if (!reuse_.keep() && multigrid_->made_for_earlier_positions()) make_structures_for_mesh(false);
    const bool reuse = filled_for_current_system() && reuse_.keep();
    if (!reuse_.keep() && !levels_match()) take_over_constraints();
    SNEDE_PETSC(SNESSetLagPreconditioner(snes_, reuse ? -1 : -2));
    if (!reuse) preconditioner_filled_ = false;
  }
  auto run = [&] {
    solve_through(ksp(), [&] { SNEDE_PETSC(SNESSolve(snes_, nullptr, u)); });
    PetscInt its = 0, lits = 0;
    SNEDE_PETSC(SNESGetConvergedReason(snes_, &reason));
    SNEDE_PETSC(SNESGetIterationNumber(snes_, &its));
    SNEDE_PETSC(SNESGetLinearSolveIterations(snes_, &lits));
    iterations += its;
    linear += lits;
    record_last_linear_solve();  // pending only with levels kept through the solve
  };
  run();
  // Near the solution the energy decrease of a Newton step falls below the round-off of Π
  // (summed over all elements), and the energy-based backtracking stops (DIVERGED_LINE_SEARCH)
  // short of the tolerance; a good preconditioner gets there in few iterations, while the
  // residual is still far above it. Full Newton steps converge quadratically there: a few
  // are tried, and kept only if they meet the criterion — otherwise the state goes back to
  // where the line search stopped, so the attempt never makes a result worse.
  // (PETSc reports some of these failures as DIVERGED_LOCAL_MIN when ‖Jᵀ F‖ is small.)
  const SNESConvergedReason stopped_by = reason;
  if (is_line_search_newton(snes_) && (reason == SNES_DIVERGED_LINE_SEARCH || reason == SNES_DIVERGED_LOCAL_MIN)) {
    VecHandle stopped;
    SNEDE_PETSC(VecDuplicate(u, stopped.out()));
    SNEDE_PETSC(VecCopy(u, stopped));
    SNESLineSearch line_search = nullptr;
    SNESLineSearchType type = nullptr;
    SNEDE_PETSC(SNESGetLineSearch(snes_, &line_search));
    SNEDE_PETSC(SNESLineSearchGetType(line_search, &type));
    const std::string previous = type;
    const PetscInt left = std::max<PetscInt>(0, options_.max_iterations - iterations);
    SNEDE_PETSC(SNESLineSearchSetType(line_search, SNESLINESEARCHBASIC));
    SNEDE_PETSC(SNESSetTolerances(snes_, 0.0, 0.0, 0.0, std::min(newton_finish_steps, left), -1));
    if (left > 0) run();
    SNEDE_PETSC(SNESSetTolerances(snes_, 0.0, 0.0, 0.0, options_.max_iterations, -1));
    SNEDE_PETSC(SNESLineSearchSetType(line_search, previous.c_str()));
    if (left == 0 || reason <= 0) {
      SNEDE_PETSC(VecCopy(stopped, u));
      reason = stopped_by;
    }
  }
  result.iterations = static_cast<int>(iterations);
  result.linear_iterations = static_cast<int>(linear);
  result.reason = std::string(SNESConvergedReasons[reason]);
  result.converged = reason > 0;
  finish(result, start, start_flops);
  if (keeps_levels_through_solve_) reuse_.record_solve(result.converged);
  return result;
}

void StaticSolver::finish(SolveResult& result, double start_seconds, double start_flops) {
  Vec u = problem_.state();
  // The verdict is checked on the final state, whatever PETSc said (§ "results, not crashes").
  if (const std::string why = problem_.inadmissible(u); !why.empty()) {
    result.converged = false;
    result.reason = why;
  }
  const ResidualCheck check = problem_.residual(u, residual_);
  result.residual_norm = vec_norm(residual_);
  // (A distributed problem's residual is NaN at an inverted state, already named above.)
  if (!check.finite || (!check.inverted && !std::isfinite(result.residual_norm))) {
    result.converged = false;
    result.reason = "DIVERGED_NONFINITE_STATE";
  }
  result.tolerance = current_tolerance();
  // A criterion that overflowed (or a load that is not finite) cannot be met honestly.
  if (result.converged && !std::isfinite(result.tolerance)) {
    result.converged = false;
    result.reason = "DIVERGED_NONFINITE_TOLERANCE";
  }
  // Converged means the stopping criterion holds at the final state, whatever stopped PETSc
  // (a line search's step tolerance, say). The factor allows CG's recursive residual to
  // differ from the recomputed one by round-off.
  if (result.converged && result.residual_norm > 2 * result.tolerance) {
    result.converged = false;
    result.reason = "DIVERGED_RESIDUAL_ABOVE_TOLERANCE (PETSc: " + result.reason + ")";
  }
  result.energy = problem_.energy(u);
  result.residual_history = history_;
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
    if (P != J || self.multigrid_) self.refill_preconditioner(snes, x);
  });
}

PetscErrorCode StaticSolver::descent_direction_callback(SNESLineSearch line_search, Vec /*u*/, Vec step,
                                                        PetscBool* changed, void* context) {
  return petsc_callback("snede Newton direction", [&] {
    StaticSolver& self = callback_owner<StaticSolver>(context, "StaticSolver");
    *changed = PETSC_FALSE;
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
    auto project = [&](Vec v) { self.problem_.project_onto_allowed_motions(v); };
    project(step);
    *changed = PETSC_TRUE;
    // An indefinite multigrid preconditioner is made positive definite for the next Newton
    // steps where its levels can be (bisection_multigrid.hpp).
    KSP linear = nullptr;
    KSPConvergedReason linear_reason = KSP_CONVERGED_ITERATING;
    SNEDE_PETSC(SNESGetKSP(snes, &linear));
    SNEDE_PETSC(KSPGetConvergedReason(linear, &linear_reason));
    // Newton moves to u − λ·step: downhill iff F·step > 0 (F = ∇Π, §2.4.3).
    PetscScalar slope = 0;
    SNEDE_PETSC(VecDot(residual, step, &slope));
    if ((linear_reason == KSP_DIVERGED_INDEFINITE_PC || !(slope > 0)) && self.multigrid_)
      self.multigrid_->prefer_positive_definite();
    if (slope > 0) return;
    // Truncated Newton (§2.4.3) stops CG at the first direction of non-positive curvature and
    // keeps its iterate so far, or at the first iteration takes the steepest descent. PETSc's CG
    // tests only for a change of the curvature's sign: when the very first direction has negative
    // curvature (a closed membrane hanging under gravity, whose compressed part wrinkles), it
    // steps along it backwards and returns an uphill direction, along which the energy line
    // search can only fail (DIVERGED_LINE_SEARCH after 25 iterations on the liver's skin). Then
    // the (preconditioned) steepest descent, scaled by the magnitude of its curvature.
    KSP ksp = nullptr;
    PC pc = nullptr;
    Mat tangent = nullptr;
    SNEDE_PETSC(SNESGetKSP(snes, &ksp));
    SNEDE_PETSC(KSPGetPC(ksp, &pc));
    SNEDE_PETSC(KSPGetOperators(ksp, &tangent, nullptr));
    SNEDE_PETSC(PCApply(pc, residual, step));
    project(step);
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
    *changed = PETSC_TRUE;
  });
}

PetscErrorCode StaticSolver::snes_converged_callback(SNES snes, PetscInt it, PetscReal xnorm, PetscReal snorm,
                                                     PetscReal fnorm, SNESConvergedReason* reason, void* context) {
  return petsc_callback("snede stopping criterion", [&] {
    auto* self = &callback_owner<StaticSolver>(context, "StaticSolver");
    stop_if_interrupted();
    // PETSc's default test catches NaN norms and the iteration limit.
    SNEDE_PETSC(SNESConvergedDefault(snes, it, xnorm, snorm, fnorm, reason, nullptr));
    fnorm *= self->system_scale_;  // the residual in newtons
    self->history_.push_back(fnorm);
    if (*reason < 0) return;
    if (!std::isfinite(self->current_tolerance())) {
      *reason = SNES_DIVERGED_FNORM_NAN;
      return;
    }
    *reason = fnorm <= self->current_tolerance() ? SNES_CONVERGED_FNORM_ABS : SNES_CONVERGED_ITERATING;
    // A Newton iteration that leaves ‖F‖ as it was made no progress: the line search took a
    // vanishing step, which near the solution means the energy cannot show the decrease any
    // more (its round-off). Stop as a line-search failure, so that the full-step finish in
    // solve_nonlinear takes over now rather than after more stalled iterations. (A trust region
    // leaves ‖F‖ as it was at every step it rejects: that is no stall.)
    const std::size_t n = self->history_.size();
    if (*reason == SNES_CONVERGED_ITERATING && is_line_search_newton(snes) && it > 0 && n >= 2 &&
        std::abs(fnorm - self->history_[n - 2]) <= newton_stall * self->history_[n - 2])
      *reason = SNES_DIVERGED_LINE_SEARCH;
  });
}

PetscErrorCode StaticSolver::ksp_converged_callback(KSP ksp, PetscInt /*iteration*/, PetscReal rnorm, KSPConvergedReason* reason,
                                                    void* context) {
  return petsc_callback("snede stopping criterion", [&] {
    auto* self = &callback_owner<StaticSolver>(context, "StaticSolver");
    (void)ksp;
    stop_if_interrupted();
    rnorm *= self->system_scale_;  // the residual in newtons
    self->history_.push_back(rnorm);
    if (!std::isfinite(rnorm) || !std::isfinite(self->current_tolerance())) {
      *reason = KSP_DIVERGED_NANORINF;
      return;
    }
    // For a linear problem the CG residual b − Jδ is the equilibrium residual −F(u + δ).
    *reason = rnorm <= self->current_tolerance() ? KSP_CONVERGED_ATOL : KSP_CONVERGED_ITERATING;
  });
}

}  // namespace snede
