#include "solve/distributed_static.hpp"

#include <petscsnes.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "core/error.hpp"
#include "core/petsc_util.hpp"

namespace snede {
namespace {

void check_conditions(const DistributedConditions& c, int dim, std::int64_t n_vertices) {
  const auto check = [&](const std::vector<std::int64_t>& ids, std::size_t values, const char* what) {
    if (values != ids.size() * static_cast<std::size_t>(dim))
      throw std::invalid_argument(std::string("DistributedStatic: ") + what + " needs " + std::to_string(dim) +
                                  " values per vertex: " + std::to_string(ids.size()) + " vertices, " +
                                  std::to_string(values) + " values");
    for (std::int64_t v : ids)
      if (v < 0 || v >= n_vertices)
        throw std::invalid_argument(std::string("DistributedStatic: ") + what + " vertex " + std::to_string(v) +
                                    " is not a vertex of the serial mesh (0.." + std::to_string(n_vertices - 1) + ")");
  };
  check(c.fixed, c.fixed_values.size(), "fixed");
  check(c.loaded, c.forces.size(), "loaded");
}

PetscErrorCode residual_callback(SNES, Vec u, Vec F, void* context) {
  return petsc_callback("snede distributed residual", [&] { static_cast<DistributedStatic*>(context)->residual(u, F); });
}

PetscErrorCode jacobian_callback(SNES, Vec u, Mat, Mat, void* context) {
  return petsc_callback("snede distributed Jacobian", [&] { static_cast<DistributedStatic*>(context)->linearize_at(u); });
}

PetscErrorCode diagonal_callback(Mat A, Vec diagonal) {
  return petsc_callback("snede distributed tangent MatGetDiagonal", [&] {
    void* context = nullptr;
    SNEDE_PETSC(MatShellGetContext(A, &context));
    static_cast<DistributedStatic*>(context)->tangent_diagonal(diagonal);
  });
}

PetscErrorCode mult_callback(Mat A, Vec d, Vec out) {
  return petsc_callback("snede distributed tangent MatMult", [&] {
    void* context = nullptr;
    SNEDE_PETSC(MatShellGetContext(A, &context));
    static_cast<DistributedStatic*>(context)->tangent_mult(d, out);
  });
}

}  // namespace

DistributedStatic::DistributedStatic(DistributedMesh& part, Material material, double thickness,
                                     const DistributedConditions& conditions)
    : part_(part), body_(*part.local, material, 1.0 /* density: no inertia or gravity here */, thickness),
      dim_(part.local->dim()) {
  check_conditions(conditions, dim_, part.n_global_vertices);
  const MPI_Comm comm = part.comm;
  const std::size_t n_local = static_cast<std::size_t>(part.local->n_points());
  const std::size_t n_dofs = n_local * static_cast<std::size_t>(dim_);
  std::unordered_map<std::int64_t, std::size_t> local_of;
  for (std::size_t v = 0; v < n_local; ++v) local_of[part.global_vertex[v]] = v;

  fixed_local_.assign(n_dofs, 0);
  fixed_value_local_.assign(n_dofs, 0.0);
  for (std::size_t k = 0; k < conditions.fixed.size(); ++k)
    if (const auto found = local_of.find(conditions.fixed[k]); found != local_of.end())
      for (int d = 0; d < dim_; ++d) {
        fixed_local_[found->second * dim_ + d] = 1;
        fixed_value_local_[found->second * dim_ + d] = conditions.fixed_values[k * dim_ + d];
      }
  std::vector<double> load_local(n_dofs, 0.0);
  for (std::size_t k = 0; k < conditions.loaded.size(); ++k)
    if (const auto found = local_of.find(conditions.loaded[k]); found != local_of.end())
      for (int d = 0; d < dim_; ++d) load_local[found->second * dim_ + d] += conditions.forces[k * dim_ + d];

  std::vector<PetscInt> rows(n_dofs);
  PetscInt n_owned = 0;
  for (std::size_t v = 0; v < n_local; ++v) {
    for (int d = 0; d < dim_; ++d) rows[v * dim_ + d] = static_cast<PetscInt>(part.global_number[v] * dim_ + d);
    n_owned += part.owned[v];
  }
  SNEDE_PETSC(VecCreateMPI(comm, n_owned * dim_, PETSC_DETERMINE, u_.out()));
  SNEDE_PETSC(VecDuplicate(u_, work_.out()));
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(u_, &start, &end));
  for (std::size_t v = 0; v < n_local; ++v)
    if (part.owned[v])
      for (int d = 0; d < dim_; ++d) {
        const PetscInt row = rows[v * dim_ + d];
        if (row < start || row >= end)
          throw std::logic_error("DistributedStatic: PETSc's vertex numbering does not match the vector's layout");
        owned_rows_.push_back(row);
        owned_local_dof_.push_back(static_cast<PetscInt>(v * dim_ + d));
        load_owned_.push_back(load_local[v * dim_ + d]);
      }

  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(n_dofs), &local_vec_));
  IS from = nullptr;
  SNEDE_PETSC(ISCreateGeneral(PETSC_COMM_SELF, static_cast<PetscInt>(n_dofs), rows.data(), PETSC_COPY_VALUES, &from));
  const PetscErrorCode made = VecScatterCreate(u_, from, local_vec_, nullptr, &scatter_);
  ISDestroy(&from);
  SNEDE_PETSC(made);

  SNEDE_PETSC(MatCreateShell(comm, n_owned * dim_, n_owned * dim_, PETSC_DETERMINE, PETSC_DETERMINE, this, tangent_.out()));
  SNEDE_PETSC(MatShellSetOperation(tangent_, MATOP_MULT, reinterpret_cast<void (*)(void)>(mult_callback)));
  SNEDE_PETSC(MatShellSetOperation(tangent_, MATOP_GET_DIAGONAL, reinterpret_cast<void (*)(void)>(diagonal_callback)));
  SNEDE_PETSC(MatSetOption(tangent_, MAT_SYMMETRIC, PETSC_TRUE));

  // The state starts at the prescribed displacements (zero elsewhere).
  PetscScalar* u = nullptr;
  SNEDE_PETSC(VecGetArray(u_, &u));
  for (std::size_t k = 0; k < owned_rows_.size(); ++k)
    u[owned_rows_[k] - start] = fixed_value_local_[static_cast<std::size_t>(owned_local_dof_[k])];
  SNEDE_PETSC(VecRestoreArray(u_, &u));
  u_local_.assign(n_dofs, 0.0);
  u_linearization_.assign(n_dofs, 0.0);
  d_local_.assign(n_dofs, 0.0);
  out_local_.assign(n_dofs, 0.0);
}

DistributedStatic::~DistributedStatic() {
  VecScatterDestroy(&scatter_);
  VecDestroy(&local_vec_);
}

void DistributedStatic::to_local(Vec global, std::vector<double>& local) {
  SNEDE_PETSC(VecScatterBegin(scatter_, global, local_vec_, INSERT_VALUES, SCATTER_FORWARD));
  SNEDE_PETSC(VecScatterEnd(scatter_, global, local_vec_, INSERT_VALUES, SCATTER_FORWARD));
  const PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArrayRead(local_vec_, &x));
  local.assign(x, x + local.size());
  SNEDE_PETSC(VecRestoreArrayRead(local_vec_, &x));
}

void DistributedStatic::add_to_global(const std::vector<double>& local, Vec global) {
  PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArray(local_vec_, &x));
  std::copy(local.begin(), local.end(), x);
  SNEDE_PETSC(VecRestoreArray(local_vec_, &x));
  SNEDE_PETSC(VecScatterBegin(scatter_, local_vec_, global, ADD_VALUES, SCATTER_REVERSE));
  SNEDE_PETSC(VecScatterEnd(scatter_, local_vec_, global, ADD_VALUES, SCATTER_REVERSE));
}

void DistributedStatic::residual(Vec u, Vec F) {
  // F = P(−f_int(u) − f_ext) + (I − P)(u − ū).
  to_local(u, u_local_);
  EvaluationReport report;
  std::vector<double> f(u_local_.size(), 0.0);
  body_.internal_forces(u_local_, f, report);
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = fixed_local_[i] ? 0.0 : -f[i];
  SNEDE_PETSC(VecZeroEntries(F));
  add_to_global(f, F);
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(F, &start, &end));
  PetscScalar* r = nullptr;
  const PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArray(F, &r));
  SNEDE_PETSC(VecGetArrayRead(u, &x));
  // An inverted element (or an overflow) on any rank makes the residual NaN on its owned rows,
  // so the norm every rank sees is NaN and SNES stops with DIVERGED_FNORM_NAN.
  const bool failed = !report.inverted.empty() || !report.domain_errors.empty();
  for (std::size_t k = 0; k < owned_rows_.size(); ++k) {
    const PetscInt i = owned_rows_[k] - start;
    const auto dof = static_cast<std::size_t>(owned_local_dof_[k]);
    r[i] = fixed_local_[dof] ? x[i] - fixed_value_local_[dof] : r[i] - load_owned_[k];
    if (failed) r[i] = std::numeric_limits<double>::quiet_NaN();
  }
  SNEDE_PETSC(VecRestoreArrayRead(u, &x));
  SNEDE_PETSC(VecRestoreArray(F, &r));
}

void DistributedStatic::tangent_mult(Vec d, Vec out) {
  // (P K P + I − P) d, K at the linearisation point.
  to_local(d, d_local_);
  for (std::size_t i = 0; i < d_local_.size(); ++i)
    if (fixed_local_[i]) d_local_[i] = 0.0;
  std::fill(out_local_.begin(), out_local_.end(), 0.0);
  EvaluationReport report;
  body_.tangent_apply(u_linearization_, d_local_, out_local_, report);
  for (std::size_t i = 0; i < out_local_.size(); ++i)
    if (fixed_local_[i]) out_local_[i] = 0.0;
  SNEDE_PETSC(VecZeroEntries(out));
  add_to_global(out_local_, out);
  set_fixed_rows(out, d, 0.0);
}

void DistributedStatic::set_fixed_rows(Vec out, Vec source, double value) {
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(out, &start, &end));
  PetscScalar* y = nullptr;
  const PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArray(out, &y));
  if (source) SNEDE_PETSC(VecGetArrayRead(source, &x));
  for (std::size_t k = 0; k < owned_rows_.size(); ++k)
    if (const PetscInt i = owned_rows_[k] - start; fixed_local_[static_cast<std::size_t>(owned_local_dof_[k])])
      y[i] = x ? x[i] : value;
  if (source) SNEDE_PETSC(VecRestoreArrayRead(source, &x));
  SNEDE_PETSC(VecRestoreArray(out, &y));
}

void DistributedStatic::tangent_diagonal(Vec diagonal) {
  // diag(P K P + I − P): the element stiffnesses' diagonals on this rank's cells, the ghosts'
  // shares added into their owners, 1 on fixed dofs (for PCJACOBI).
  std::fill(out_local_.begin(), out_local_.end(), 0.0);
  const auto d = static_cast<std::size_t>(dim_);
  body_.for_each_element_stiffness(u_linearization_, [&](ElementId, std::span<const VertexId> vertices,
                                                           std::span<const double> K) {
    const std::size_t n = vertices.size() * d;
    for (std::size_t row = 0; row < n; ++row)
      out_local_[static_cast<std::size_t>(vertices[row / d]) * d + row % d] += K[row * n + row];
  });
  for (std::size_t i = 0; i < out_local_.size(); ++i)
    if (fixed_local_[i]) out_local_[i] = 0.0;
  SNEDE_PETSC(VecZeroEntries(diagonal));
  add_to_global(out_local_, diagonal);
  set_fixed_rows(diagonal, nullptr, 1.0);
}

SolveResult DistributedStatic::solve(const std::string& method, const std::string& preconditioner, double rtol,
                                     int max_iterations, const std::string& prefix) {
  if (method != "cg" && method != "newton")
    throw std::invalid_argument("DistributedStatic.solve: method must be \"cg\" or \"newton\", got \"" + method + "\"");
  if (preconditioner != "none" && preconditioner != "jacobi")
    throw std::invalid_argument("DistributedStatic.solve: preconditioner must be \"none\" or \"jacobi\", got \"" +
                                preconditioner + "\"");
  if (!(rtol > 0)) throw std::invalid_argument("DistributedStatic.solve: rtol must be positive");
  const double start = wall_seconds();
  SnesHandle snes;
  SNEDE_PETSC(SNESCreate(part_.comm, snes.out()));
  SNEDE_PETSC(SNESSetOptionsPrefix(snes, prefix.c_str()));
  SNEDE_PETSC(SNESSetFunction(snes, work_, residual_callback, this));
  // The shell needs no assembly: SNES's Jacobian step only sets the linearisation point.
  SNEDE_PETSC(SNESSetJacobian(snes, tangent_, tangent_, jacobian_callback, this));
  KSP ksp = nullptr;
  PC pc = nullptr;
  SNEDE_PETSC(SNESGetKSP(snes, &ksp));
  SNEDE_PETSC(KSPSetType(ksp, KSPCG));
  SNEDE_PETSC(KSPGetPC(ksp, &pc));
  SNEDE_PETSC(PCSetType(pc, preconditioner == "jacobi" ? PCJACOBI : PCNONE));
  if (method == "cg") {
    SNEDE_PETSC(SNESSetType(snes, SNESKSPONLY));
    SNEDE_PETSC(KSPSetTolerances(ksp, rtol, 0.0, PETSC_DEFAULT, max_iterations));
  } else {
    SNEDE_PETSC(SNESSetType(snes, SNESNEWTONLS));
    SNEDE_PETSC(SNESSetTolerances(snes, 0.0, rtol, 0.0, max_iterations, PETSC_DEFAULT));
  }
  SNEDE_PETSC(SNESSetFromOptions(snes));
  SolveResult result;
  SNEDE_PETSC(SNESSolve(snes, nullptr, u_));
  SNESConvergedReason reason = SNES_CONVERGED_ITERATING;
  SNEDE_PETSC(SNESGetConvergedReason(snes, &reason));
  PetscInt iterations = 0, linear = 0;
  SNEDE_PETSC(SNESGetIterationNumber(snes, &iterations));
  SNEDE_PETSC(SNESGetLinearSolveIterations(snes, &linear));
  if (method == "cg") {
    KSPConvergedReason ksp_reason = KSP_CONVERGED_ITERATING;
    SNEDE_PETSC(KSPGetConvergedReason(ksp, &ksp_reason));
    result.converged = ksp_reason > 0 && reason >= 0;
    // CG's own reason (DIVERGED_ITS, DIVERGED_INDEFINITE_MAT), unless CG never ran.
    result.reason = ksp_reason != KSP_CONVERGED_ITERATING ? KSPConvergedReasons[ksp_reason] : SNESConvergedReasons[reason];
    result.iterations = static_cast<int>(linear);
  } else {
    result.converged = reason > 0;
    result.reason = SNESConvergedReasons[reason];
    result.iterations = static_cast<int>(iterations);
    result.linear_iterations = static_cast<int>(linear);
  }
  residual(u_, work_);
  PetscReal norm = 0;
  SNEDE_PETSC(VecNorm(work_, NORM_2, &norm));
  result.residual_norm = norm;
  if (!std::isfinite(norm)) result.converged = false;  // an inverted element is never converged
  result.energy = energy();
  result.seconds = wall_seconds() - start;
  return result;
}

double DistributedStatic::energy() {
  to_local(u_, u_local_);
  EvaluationReport report;
  double local = body_.energy(u_local_, report);
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(u_, &start, &end));
  const PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArrayRead(u_, &x));
  for (std::size_t k = 0; k < owned_rows_.size(); ++k) local -= load_owned_[k] * x[owned_rows_[k] - start];
  SNEDE_PETSC(VecRestoreArrayRead(u_, &x));
  double total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, part_.comm);
  return total;
}

void DistributedStatic::linearize_at(Vec u) { to_local(u, u_linearization_); }

std::vector<double> DistributedStatic::local_displacement() {
  std::vector<double> u(u_local_.size());
  to_local(u_, u);
  return u;
}

}  // namespace snede
