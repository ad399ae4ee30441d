#include "multigrid/multigrid.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "core/error.hpp"

namespace snede {
namespace {

// Reused Chebyshev bounds: the estimate times this (PETSc's own estimate-based default is
// 1.1), and the lower end of the smoothed interval as a fraction of the upper (PETSc's 0.1).
constexpr double reused_bound_safety = 1.2;
constexpr double chebyshev_lower_fraction = 0.1;

}  // namespace

GalerkinMultigrid::GalerkinMultigrid(Model& fine)
    : fine_(fine),
      revision_(fine.body().mesh().connectivity().revision()),
      topology_revision_(fine.body().mesh().connectivity().topology_revision()),
      constraints_(fine.constraints().projection_fingerprint()) {}

bool GalerkinMultigrid::matches_mesh() const {
  return fine_.body().mesh().connectivity().revision() == revision_;
}

bool GalerkinMultigrid::carry_over_moved_vertices() {
  const Connectivity& mesh = fine_.body().mesh().connectivity();
  if (mesh.topology_revision() != topology_revision_) return false;
  revision_ = mesh.revision();
  carried_ = true;
  return true;
}

bool GalerkinMultigrid::matches() const {
  return matches_mesh() && fine_.constraints().projection_fingerprint() == constraints_;
}

void set_chebyshev_jacobi_smoother(KSP smoother, const SolverOptions& options, double largest_bound,
                                   bool point_blocks) {
  options.use_for(smoother);
  SNEDE_PETSC(KSPSetType(smoother, KSPCHEBYSHEV));
  if (largest_bound > 0) {
    // The spectrum of the Jacobi-scaled operator hardly depends on h, the state or the
    // constraints: bounds estimated once serve later set-ups, which then skip the estimate.
    const double largest = reused_bound_safety * largest_bound;
    SNEDE_PETSC(KSPChebyshevEstEigSet(smoother, 0, 0, 0, 0));
    SNEDE_PETSC(KSPChebyshevSetEigenvalues(smoother, largest, chebyshev_lower_fraction * largest));
  } else {
    SNEDE_PETSC(KSPChebyshevEstEigSet(smoother, PETSC_DECIDE, PETSC_DECIDE, PETSC_DECIDE, PETSC_DECIDE));
  }
  PC jacobi = nullptr;
  SNEDE_PETSC(KSPGetPC(smoother, &jacobi));
  options.use_for(jacobi);
  SNEDE_PETSC(PCSetType(jacobi, point_blocks ? PCPBJACOBI : PCJACOBI));
}

std::vector<double> chebyshev_estimates(PC pc) {
  PetscInt n = 0;
  SNEDE_PETSC(PCMGGetLevels(pc, &n));
  std::vector<double> largest;
  for (PetscInt l = 1; l < n; ++l) {
    KSP smoother = nullptr, estimator = nullptr;
    SNEDE_PETSC(PCMGGetSmoother(pc, l, &smoother));
    PetscBool chebyshev = PETSC_FALSE;
    SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(smoother), KSPCHEBYSHEV, &chebyshev));
    if (!chebyshev) return {};
    SNEDE_PETSC(KSPChebyshevEstEigGetKSP(smoother, &estimator));
    if (!estimator) return {};
    PetscReal emax = 0, emin = 0;
    SNEDE_PETSC(KSPComputeExtremeSingularValues(estimator, &emax, &emin));
    if (!(emax > 0) || !std::isfinite(emax)) return {};
    largest.push_back(emax);
  }
  return largest;
}

void set_direct_coarse_solve(PC pc, const SolverOptions& options) {
  KSP coarse = nullptr;
  SNEDE_PETSC(PCMGGetCoarseSolve(pc, &coarse));
  options.use_for(coarse);
  SNEDE_PETSC(KSPSetType(coarse, KSPPREONLY));
  PC direct = nullptr;
  SNEDE_PETSC(KSPGetPC(coarse, &direct));
  options.use_for(direct);
  PetscMPIInt ranks = 1;
  SNEDE_PETSC(MPI_Comm_size(PetscObjectComm(reinterpret_cast<PetscObject>(pc)), &ranks));
  if (ranks > 1) {
    // On several ranks every rank factors the whole (small) coarsest level (PCREDUNDANT).
    SNEDE_PETSC(PCSetType(direct, PCREDUNDANT));
    KSP inner = nullptr;
    SNEDE_PETSC(PCRedundantGetKSP(direct, &inner));
    options.use_for(inner);
    SNEDE_PETSC(KSPGetPC(inner, &direct));
    options.use_for(direct);
  }
  SNEDE_PETSC(PCSetType(direct, PCLU));
  // A cut can leave a piece held by a hinge (an edge, a vertex) whose coarse stiffness is
  // singular: an exact zero pivot is shifted instead of filling the step with NaN (measured: the
  // 63k liver's loop stopped with DIVERGED_NONFINITE_STATE at the 15th move without it).
  SNEDE_PETSC(PCFactorSetShiftType(direct, MAT_SHIFT_NONZERO));
}

void GalerkinMultigrid::configure_levels(PC pc, std::vector<Mat> interpolations, const SolverOptions& options) {
  const auto n = static_cast<PetscInt>(interpolations.size()) + 1;
  SNEDE_PETSC(PCSetType(pc, PCMG));
  SNEDE_PETSC(PCMGSetLevels(pc, n, nullptr));
  SNEDE_PETSC(PCMGSetType(pc, PC_MG_MULTIPLICATIVE));
  // The products are snede's own (update(), galerkin_product.hpp), not PCMG's.
  SNEDE_PETSC(PCMGSetGalerkin(pc, PC_MG_GALERKIN_NONE));
  for (PetscInt l = 1; l < n; ++l) {
    SNEDE_PETSC(PCMGSetInterpolation(pc, l, interpolations[l - 1]));
    KSP smoother = nullptr;
    SNEDE_PETSC(PCMGGetSmoother(pc, l, &smoother));
    // Bounds from earlier levels are not reused: Chebyshev with a stale bound diverged (Newton
    // stalled after the third move through the liver). The estimate costs a few products.
    // The finest level's matrix is the assembled tangent, with a vertex's components in a
    // block: Jacobi by those blocks couples them as elasticity does. On the livers' cut loops
    // (studies/benchmarks/interactive_cut.py) it took 13.7 CG iterations per Newton step against 15.6
    // (20k and 60k tetrahedra) and 6–8 % less time; on the bisected blocks 3 % more at most.
    set_chebyshev_jacobi_smoother(smoother, options, 0.0, l == n - 1);
  }
  set_direct_coarse_solve(pc, options);
  pc_ = pc;
  interpolations_ = std::move(interpolations);
  fine_matrix_ = nullptr;
  coarse_.clear();
}

std::unique_ptr<CoarseProduct> GalerkinMultigrid::galerkin_product(Mat finer, PetscInt level) const {
  return petsc_galerkin_product(finer, interpolations_[level]);
}

void GalerkinMultigrid::update(Vec, Mat assembled_tangent) {
  if (!pc_) throw std::logic_error("GalerkinMultigrid::update before configure");
  if (!assembled_tangent) throw std::logic_error("Galerkin levels need the assembled tangent");
  if (assembled_tangent == fine_matrix_) {
    for (auto& product : coarse_) product->recompute();
    return;
  }
  coarse_.clear();
  Mat finer = assembled_tangent;
  for (auto level = static_cast<PetscInt>(interpolations_.size()) - 1; level >= 0; --level) {
    std::unique_ptr<CoarseProduct> product = galerkin_product(finer, level);
    KSP solver = nullptr;
    if (level == 0) {
      SNEDE_PETSC(PCMGGetCoarseSolve(pc_, &solver));
    } else {
      SNEDE_PETSC(PCMGGetSmoother(pc_, level, &solver));
    }
    SNEDE_PETSC(KSPSetOperators(solver, product->matrix(), product->matrix()));
    finer = product->matrix();
    coarse_.push_back(std::move(product));
  }
  fine_matrix_ = assembled_tangent;
}

}  // namespace snede
