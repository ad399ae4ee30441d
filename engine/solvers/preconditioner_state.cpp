#include "solvers/preconditioner_state.hpp"

#include <stdexcept>
#include <utility>

#include "core/error.hpp"
#include "core/log_event.hpp"

namespace snede {
namespace {

// GAMG keeps its interpolation when the matrix changes (PETSc 3.18's default), and with it the
// bounds its Chebyshev smoothers took from the first set-up's smoothed-aggregation estimate.
// Newton refills the matrix at every iteration, and a tangent that stiffened past those bounds
// made the V-cycle indefinite (DIVERGED_INDEFINITE_PC, then DIVERGED_LINE_SEARCH: a neo-Hookean
// cantilever of 30 × 6 × 6 cubes, a box with vertices sliding along oblique lines; issue 48
// item 8). The smoothers estimate their own bounds instead, again whenever their operator
// changes (-<prefix>pc_gamg_use_sa_esteig, read afterwards, overrides).
void configure_gamg(PC pc, const std::string& type) {
  if (type == PCGAMG) SNEDE_PETSC(PCGAMGSetUseSAEstEig(pc, PETSC_FALSE));
}

}  // namespace

PreconditionerState::PreconditionerState(Problem& problem, std::unique_ptr<LevelSource> levels,
                                         SolverOptions& database, const StaticOptions& options)
    : problem_(problem),
      level_source_(std::move(levels)),
      database_(database),
      options_(options),
      reuse_(database.number_option(options.options_prefix + "mg_refresh_ratio",
                                    PreconditionerReuse::default_refresh_ratio)),
      rebuild_after_edits_(database.bool_option(options.options_prefix + "rebuild_after_edits", false)) {
  const std::string& prefix = options_.options_prefix;
  // The command line (copied into the solver's database) wins over the argument.
  type_ = database_.string_option(prefix + "pc_type")
              .value_or(options_.preconditioner.empty() ? std::string("auto") : options_.preconditioner);
  if (type_ == "auto") {
    automatic_ = true;
    type_ = automatic_type();
    // -<prefix>pc_type auto is snede's: PETSc, which reads the option again, must see the choice.
    if (database_.string_option(prefix + "pc_type")) database_.set_string_option(prefix + "pc_type", type_);
  }
  if (options_.method == StaticMethod::nonlinear_cg && type_ != PCNONE)
    throw std::invalid_argument("a preconditioner ('" + type_ + "') applies to the CG of methods 'cg' and 'newton'; "
                                "nonlinear CG ('ncg') takes no preconditioner");
  if (type_ != PCMG && !automatic_ && database_.string_option(prefix + "mg_refresh_ratio"))
    throw std::invalid_argument("-" + prefix + "mg_refresh_ratio applies to the preconditioner 'mg'; this solver's is '" +
                                type_ + "'");
  PetscMPIInt ranks = 1;
  SNEDE_PETSC(MPI_Comm_size(problem_.comm(), &ranks));
  // PETSc's incomplete factorisations are sequential: PETSc's own error names no remedy.
  if (ranks > 1 && (type_ == PCILU || type_ == PCICC))
    throw std::invalid_argument("preconditioner '" + type_ + "' factors a whole matrix on one process; on " +
                                std::to_string(ranks) + " MPI ranks use 'bjacobi' (" + type_ +
                                " of each rank's block: -" + prefix + "sub_pc_type " + type_ + "), 'mg' or 'gamg'");
  // Jacobi reads the shell's diagonal (MatGetDiagonal), mg builds its own levels (and needs
  // entries only for Galerkin levels); every other PC needs entries.
  pc_needs_matrix_ = type_ != PCNONE && type_ != PCJACOBI && type_ != PCMG;
  needs_matrix_ = pc_needs_matrix_;
}

std::string PreconditionerState::automatic_type() const {
  // Multigrid from options.multigrid_from_cells (static_options.hpp), never for nonlinear CG.
  if (options_.method == StaticMethod::nonlinear_cg || problem_.n_global_cells() < options_.multigrid_from_cells ||
      !level_source_ || !level_source_->has_levels())
    return PCNONE;
  return PCMG;
}

bool PreconditionerState::wants_other_type() const { return automatic_ && automatic_type() != type_; }

void PreconditionerState::choose_type_again() {
  const std::string previous = type_;
  type_ = automatic_type();
  needs_matrix_ = pc_needs_matrix_;  // false: the automatic choices are none and mg
  try {
    make_levels();  // sets needs_matrix_ for Galerkin levels
  } catch (...) {
    type_ = previous;
    multigrid_.reset();
    throw;
  }
  const std::string pc_type_option = options_.options_prefix + "pc_type";
  if (database_.string_option(pc_type_option)) database_.set_string_option(pc_type_option, type_);
  assembled_.reset();
  filled_ = false;
}

void PreconditionerState::make_missing_levels() {
  if (!multigrid_) make_levels();
}

void PreconditionerState::make_levels(Multigrid* earlier) {
  multigrid_.reset();
  if (type_ != PCMG) return;
  if (!level_source_) throw std::invalid_argument("the preconditioner 'mg' has no levels for this problem");
  multigrid_ = level_source_->make_levels(database_, options_.options_prefix, earlier, rebuild_after_edits_);
  needs_matrix_ = pc_needs_matrix_ || multigrid_->needs_assembled_tangent();
  ++multigrid_builds_;
}

MatrixFormat PreconditionerState::assembled_tangent_format() const {
  // GAMG works on AIJ, Galerkin levels on what their products read.
  return pc_needs_matrix_ || !multigrid_ ? MatrixFormat::aij : multigrid_->assembled_tangent_format();
}

Mat PreconditionerState::matrix() {
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
    filled_ = false;
    tangent_follows_edits_ = false;  // a new tangent is assembled
  }
  return assembled_->mat();
}

void PreconditionerState::configure(PC pc) {
  database_.use_for(pc);
  SNEDE_PETSC(PCSetType(pc, type_.c_str()));
  configure_gamg(pc, type_);
  // A multigrid PC smooths its finest level with the assembled matrix, not the shell (each
  // shell product costs several assembled ones); -<prefix>pc_use_amat turns it back.
  SNEDE_PETSC(PCSetUseAmat(pc, PETSC_FALSE));
  if (multigrid_) configure_levels(pc);
}

void PreconditionerState::configure_after_reset(PC pc) {
  if (!needs_matrix_ && type_ != PCMG) return;
  SNEDE_PETSC(PCSetType(pc, PCNONE));
  SNEDE_PETSC(PCSetType(pc, type_.c_str()));
  configure_gamg(pc, type_);
  if (multigrid_) configure_levels(pc);
  SNEDE_PETSC(PCSetFromOptions(pc));
}

void PreconditionerState::configure_levels(PC pc) {
  // Bounds from another number of levels do not apply.
  if (smoother_bounds_.size() + 1 != static_cast<std::size_t>(multigrid_->n_levels())) smoother_bounds_.clear();
  multigrid_->configure(pc, database_, smoother_bounds_);
  // The finest level smooths with the PC's matrix: the assembled tangent for Galerkin levels
  // (their products need entries), else the shell.
  SNEDE_PETSC(PCSetUseAmat(pc, PETSC_FALSE));
  // The levels come with their own operators and interpolations: PCMG must not coarsen the
  // SNES's shell DM (which it would try after a mesh change, when the PC gets that DM).
  SNEDE_PETSC(PCSetDM(pc, nullptr));
  filled_ = false;
}

bool PreconditionerState::follow_changes(bool resized, double scale, PC pc) {
  const bool stale_matrix = needs_matrix_ && (!assembled_ || !assembled_->matches());
  const bool stale_levels = multigrid_ && !multigrid_->matches();
  if (!resized && !stale_matrix && !stale_levels) return false;
  if (!resized && !stale_matrix && multigrid_->matches_mesh()) {
    // Only the constraints changed (a needle's stick-slip): a change of a few vertices. Galerkin
    // levels that Newton keeps across solves keep their interpolation, made for the earlier
    // constraints, and are refilled at the next solve (fine matrix and Galerkin products, no new
    // grid or structure); Newton's step is projected onto the allowed motions. They take the
    // constraints over once they show their age (lag_for_solve).
    if (!lags_constraint_changes()) take_over_constraints(pc);
    return false;
  }
  if (!resized && carry_over_moved_vertices()) return false;
  make_structures(scale);
  return true;
}

void PreconditionerState::make_structures(double scale) {
  // A flip or a cut changes the sparsity; vertices moved alone (a cut's snap) keep it, and the
  // values are filled again for the new reference shapes.
  if (assembled_ && !rebuild_after_edits_ && assembled_->follow_moved_vertices())
    filled_ = false;
  else if (!tangent_follows_edits(scale))
    assembled_.reset();
  const std::unique_ptr<Multigrid> earlier = std::move(multigrid_);
  make_levels(earlier.get());
}

bool PreconditionerState::tangent_follows_edits(double scale) {
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
  const ScaledOperator scaled(problem_, scale);
  std::unique_ptr<AssembledProblemTangent> edited =
      assembled_->follow_edits(lags_constraint_changes() ? problem_.state() : nullptr);
  if (!edited) return false;
  assembled_ = std::move(edited);
  ++sparsity_builds_;
  ++sparsity_edits_;
  filled_ = false;  // the PC is made for the new matrix
  tangent_follows_edits_ = assembled_->filled();
  tangent_edited_at_scale_ = scale;
  return true;
}

bool PreconditionerState::carry_over_moved_vertices() {
  // A cut's snap moves a vertex or two onto the blade and changes no element (half of a
  // scalpel's moves, issue 49): Galerkin levels that Newton keeps across solves keep serving,
  // with the tangent of the earlier shapes, until they show their age; then the next Newton
  // solve makes them anew for the shapes of now. The operator of every solve is the exact tangent.
  if (rebuild_after_edits_ || !assembled_ || !multigrid_ || !lags_constraint_changes()) return false;
  if (!multigrid_->carry_over_moved_vertices()) return false;
  if (!assembled_->follow_moved_vertices()) throw std::logic_error("levels carried over a change of elements");
  return true;
}

void PreconditionerState::take_over_constraints(PC pc) {
  // The same levels take the constraints over (new levels if one is no longer held), on a fresh
  // PC; the solver objects stay as they are.
  SNEDE_PETSC(PCSetType(pc, PCNONE));
  if (!multigrid_->follow_constraints()) make_levels();
  configure_levels(pc);
  SNEDE_PETSC(PCSetFromOptions(pc));
}

bool PreconditionerState::filled_for(double scale) const {
  return filled_ && filled_at_scale_ == scale && filled_for_constraints_ == problem_.projection_fingerprint();
}

void PreconditionerState::fill(Vec u, double scale) {
  // A tangent made from the earlier one is filled already, unless the system's scale changed since.
  if (assembled_ && !(tangent_follows_edits_ && tangent_edited_at_scale_ == scale)) {
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
  ++fills_;
  filled_ = true;
  filled_at_scale_ = scale;
  filled_for_constraints_ = problem_.projection_fingerprint();
}

bool PreconditionerState::keeps_galerkin_levels() const {
  return options_.method == StaticMethod::newton && multigrid_ && multigrid_->needs_assembled_tangent() &&
         !database_.string_option(options_.options_prefix + "snes_lag_preconditioner");
}

bool PreconditionerState::lags_constraint_changes() const { return keeps_galerkin_levels() && reuse_.keep(); }

bool PreconditionerState::begin_newton_solve() {
  // Galerkin levels (an assembled tangent, its products with the interpolation, a coarse
  // factorisation) are filled at the first Newton iteration of a solve and kept through its other
  // iterations until they show their age (preconditioner_reuse.hpp), unless the options lag
  // otherwise: filling them at every iteration cost more than the CG iterations it saves
  // (docs/results/interactive.md). While the mesh and the projections stay the same, the next
  // solves keep them too, by the same test. After a change of constraints alone (a needle's
  // stick-slip) the levels are refilled with the interpolation of the earlier constraints
  // (follow_changes) until they show their age: then they take the constraints of now over.
  keeps_levels_through_solve_ = keeps_galerkin_levels();
  linear_solve_pending_ = false;
  return keeps_levels_through_solve_;
}

bool PreconditionerState::structures_outlived() const {
  return !reuse_.keep() && multigrid_->made_for_earlier_positions();
}

PetscInt PreconditionerState::lag_for_solve(double scale, PC pc) {
  const bool reuse = filled_for(scale) && reuse_.keep();
  if (!reuse_.keep() && !multigrid_->matches()) take_over_constraints(pc);
  if (!reuse) filled_ = false;
  return reuse ? -1 : -2;
}

void PreconditionerState::refill_for_newton(SNES snes, Vec x, double scale, KSP ksp) {
  PetscInt lag = 1, iteration = 0;
  SNEDE_PETSC(SNESGetLagPreconditioner(snes, &lag));
  SNEDE_PETSC(SNESGetIterationNumber(snes, &iteration));
  // Galerkin levels kept through a solve are filled again at the state of now when the last
  // linear solve failed with them (kept levels made Newton's line search fail on the 63k liver),
  // or when they show their age (preconditioner_reuse.hpp: on the static 98k block the CG per
  // Newton iteration grew from 3 to 42 over 13 iterations with the levels of the first). Aged
  // levels that lag a change of constraints (a needle's stick-slip) take the constraints over at
  // the next solve instead: refilled on their earlier interpolation they keep the old baseline
  // (preconditioner_reuse.hpp), and would be refilled at every later iteration.
  if (keeps_levels_through_solve_) {
    const bool failed = record_last_linear_solve(ksp);
    if (lag == -1 && (failed || (!reuse_.keep() && multigrid_->matches()))) {
      SNEDE_PETSC(SNESSetLagPreconditioner(snes, -2));
      lag = -2;
      filled_ = false;
    }
    linear_solve_pending_ = true;
  }
  // As SNES decides whether to rebuild the PC: -1 never again (-2 becomes -1 once built), k > 1
  // every k-th iteration.
  const bool lagged = (lag == -1 || (lag > 1 && iteration % lag != 0)) && filled_;
  if (lagged) return;
  fill(x, scale);
  // Levels refilled on an interpolation of earlier constraints do not set a new baseline.
  if (keeps_levels_through_solve_) reuse_.filled(multigrid_->matches());
}

bool PreconditionerState::record_last_linear_solve(KSP ksp) {
  if (!linear_solve_pending_) return false;
  linear_solve_pending_ = false;
  PetscInt iterations = 0;
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  SNEDE_PETSC(KSPGetIterationNumber(ksp, &iterations));
  SNEDE_PETSC(KSPGetConvergedReason(ksp, &reason));
  reuse_.record_linear_solve(static_cast<int>(iterations), reason > 0);
  return reason < 0;
}

void PreconditionerState::end_newton_solve(bool converged) {
  if (keeps_levels_through_solve_) reuse_.record_solve(converged);
}

void PreconditionerState::remember_smoother_bounds(PC pc) {
  if (!multigrid_ || !smoother_bounds_.empty()) return;
  PetscBool is_mg = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCMG, &is_mg));
  if (is_mg) smoother_bounds_ = chebyshev_estimates(pc);  // called after a solve: set up
}

}  // namespace snede
