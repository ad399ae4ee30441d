#include "solve/distributed_static.hpp"

#include <petscsnes.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <variant>

#include "core/error.hpp"
#include "core/rank_agreement.hpp"
#include "core/petsc_util.hpp"
#include "mesh/element_quality.hpp"
#include "fem/stable_time_step.hpp"
#include "solve/failed_solve.hpp"
#include "solve/static_solver.hpp"
#include "solve/stopping.hpp"

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
  if (!c.gravity.empty() && c.gravity.size() != static_cast<std::size_t>(dim))
    throw std::invalid_argument("DistributedStatic: gravity needs " + std::to_string(dim) + " components, got " +
                                std::to_string(c.gravity.size()));
  for (double g : c.gravity)
    if (!std::isfinite(g)) throw std::invalid_argument("DistributedStatic: gravity must be finite");
}

// The same material, density, thickness and conditions on every rank, or the same error on
// every rank naming what differs: a rank with other loads would silently solve another problem.
// Named as the Python arguments (DistributedStatic(part, material, fixed=, fixed_values=, ...)).
bool require_same_inputs_everywhere(MPI_Comm comm, const Material& material, double density, double thickness,
                                    const DistributedConditions& c) {
  const Lame lame = std::visit([](const auto& m) { return m.lame; }, material);
  RankAgreement("DistributedStatic")
      .input("material", InputDigest().add(static_cast<double>(material.index())).add(lame.lambda).add(lame.mu))
      .input("density", density)
      .input("thickness", thickness)
      .input("fixed", c.fixed)
      .input("fixed_values", c.fixed_values)
      .input("forces", InputDigest().add(c.loaded).add(c.forces))
      .input("gravity", c.gravity)
      .require(comm);
  return true;
}

PetscErrorCode residual_callback(SNES snes, Vec u, Vec F, void* context) {
  return petsc_callback("snede distributed residual", [&] {
    // Every rank agrees on the verdict, so line searches shorten the same step everywhere.
    if (!static_cast<DistributedStatic*>(context)->residual(u, F).admissible())
      SNEDE_PETSC(SNESSetFunctionDomainError(snes));
  });
}

PetscErrorCode jacobian_callback(SNES, Vec u, Mat J, Mat P, void* context) {
  return petsc_callback("snede distributed Jacobian", [&] {
    auto* problem = static_cast<DistributedStatic*>(context);
    problem->linearize_at(u);
    if (P != J) problem->assemble_tangent();
  });
}

// The (6.8)/(6.9) rule on the true residual, as the serial StaticSolver's tests; PETSc's default
// test first catches NaN norms and the iteration limit.
PetscErrorCode snes_rule_callback(SNES snes, PetscInt it, PetscReal xnorm, PetscReal snorm, PetscReal fnorm,
                                  SNESConvergedReason* reason, void* context) {
  return petsc_callback("snede distributed stopping criterion", [&] {
    SNEDE_PETSC(SNESConvergedDefault(snes, it, xnorm, snorm, fnorm, reason, nullptr));
    if (*reason < 0) return;
    const double tolerance = static_cast<DistributedStatic*>(context)->stopping_tolerance();
    if (!std::isfinite(tolerance)) *reason = SNES_DIVERGED_FNORM_NAN;
    else *reason = fnorm <= tolerance ? SNES_CONVERGED_FNORM_ABS : SNES_CONVERGED_ITERATING;
  });
}

// For a linear problem CG's residual b − Jδ is −F(u₀ + δ), so the rule applies to it directly.
PetscErrorCode ksp_rule_callback(KSP, PetscInt, PetscReal rnorm, KSPConvergedReason* reason, void* context) {
  return petsc_callback("snede distributed stopping criterion", [&] {
    const double tolerance = static_cast<DistributedStatic*>(context)->stopping_tolerance();
    if (!std::isfinite(rnorm) || !std::isfinite(tolerance)) *reason = KSP_DIVERGED_NANORINF;
    else *reason = rnorm <= tolerance ? KSP_CONVERGED_ATOL : KSP_CONVERGED_ITERATING;
  });
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

DistributedStatic::DistributedStatic(DistributedMesh& part, Material material, double density, double thickness,
                                     const DistributedConditions& conditions)
    : part_(part),
      inputs_agreed_(require_same_inputs_everywhere(part.comm, material, density, thickness, conditions)),
      body_(*part.local, material, density, thickness),
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

  std::vector<PetscInt>& rows = local_rows_;
  rows.resize(n_dofs);
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

  if (!conditions.gravity.empty()) {
    // Each rank's cells load their corners; ghosts' shares go to the owners.
    SNEDE_PETSC(VecZeroEntries(work_));
    add_to_global(body_.gravity_forces(conditions.gravity), work_);
    const PetscScalar* g = nullptr;
    SNEDE_PETSC(VecGetArrayRead(work_, &g));
    for (std::size_t k = 0; k < owned_rows_.size(); ++k) load_owned_[k] += g[owned_rows_[k] - start];
    SNEDE_PETSC(VecRestoreArrayRead(work_, &g));
  }

  set_displacement({});
  u_local_.assign(n_dofs, 0.0);
  u_linearization_.assign(n_dofs, 0.0);
  d_local_.assign(n_dofs, 0.0);
  out_local_.assign(n_dofs, 0.0);
}

void DistributedStatic::set_displacement(std::span<const double> serial) {
  RankAgreement("DistributedStatic.set_displacement").input("displacement", serial).require(part_.comm);
  const auto expected = static_cast<std::size_t>(part_.n_global_vertices * dim_);
  if (!serial.empty() && serial.size() != expected)
    throw std::invalid_argument("DistributedStatic.set_displacement: needs " + std::to_string(expected) +
                                " values (n_global_vertices × dim), got " + std::to_string(serial.size()));
  for (double x : serial)
    if (!std::isfinite(x)) throw std::invalid_argument("DistributedStatic.set_displacement: values must be finite");
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(u_, &start, &end));
  PetscScalar* u = nullptr;
  SNEDE_PETSC(VecGetArray(u_, &u));
  for (std::size_t k = 0; k < owned_rows_.size(); ++k) {
    const auto dof = static_cast<std::size_t>(owned_local_dof_[k]);
    const auto vertex = static_cast<std::size_t>(part_.global_vertex[dof / dim_]);
    u[owned_rows_[k] - start] = fixed_local_[dof] ? fixed_value_local_[dof]
                                : serial.empty()  ? 0.0
                                                  : serial[vertex * dim_ + dof % dim_];
  }
  SNEDE_PETSC(VecRestoreArray(u_, &u));
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

ResidualCheck DistributedStatic::residual(Vec u, Vec F) {
  // F = P(−f_int(u) − f_ext) + (I − P)(u − ū); the fixed rows' −f_int − f_ext are the reactions.
  to_local(u, u_local_);
  EvaluationReport report;
  std::vector<double> f(u_local_.size(), 0.0);
  body_.internal_forces(u_local_, f, report);
  for (double& x : f) x = -x;
  SNEDE_PETSC(VecZeroEntries(F));
  add_to_global(f, F);
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(F, &start, &end));
  PetscScalar* r = nullptr;
  const PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArray(F, &r));
  SNEDE_PETSC(VecGetArrayRead(u, &x));
  const bool inverted = !report.inverted.empty() && forbids_inversion(body_.material());
  // Ranks with an inverted element, ranks with a non-finite one, ‖reactions‖².
  double sums[3] = {inverted ? 1.0 : 0.0, report.domain_errors.empty() ? 0.0 : 1.0, 0.0};
  for (std::size_t k = 0; k < owned_rows_.size(); ++k) {
    const PetscInt i = owned_rows_[k] - start;
    const auto dof = static_cast<std::size_t>(owned_local_dof_[k]);
    r[i] -= load_owned_[k];
    if (fixed_local_[dof]) {
      sums[2] += r[i] * r[i];
      r[i] = x[i] - fixed_value_local_[dof];
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, sums, 3, MPI_DOUBLE, MPI_SUM, part_.comm);
  last_reaction_norm_ = std::sqrt(sums[2]);
  last_failure_ = sums[1] > 0 ? "DIVERGED_NONFINITE_STATE" : sums[0] > 0 ? "DIVERGED_INVERTED_ELEMENTS" : "";
  const ResidualCheck check{sums[1] == 0, sums[0] > 0};
  // A failure on any rank makes the residual NaN everywhere: no solver can call it converged.
  if (!check.admissible())
    for (std::size_t k = 0; k < owned_rows_.size(); ++k) r[owned_rows_[k] - start] = std::numeric_limits<double>::quiet_NaN();
  SNEDE_PETSC(VecRestoreArrayRead(u, &x));
  SNEDE_PETSC(VecRestoreArray(F, &r));
  return check;
}

std::string DistributedStatic::inadmissible(Vec u) {
  VecHandle scratch;
  SNEDE_PETSC(VecDuplicate(u, scratch.out()));
  const double reaction_norm = last_reaction_norm_;  // the caller's latest residual's
  residual(u, scratch);
  last_reaction_norm_ = reaction_norm;
  return last_failure_;
}

void DistributedStatic::enforce_constraints(Vec u) {
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(u, &start, &end));
  PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArray(u, &x));
  for (std::size_t k = 0; k < owned_rows_.size(); ++k)
    if (const auto dof = static_cast<std::size_t>(owned_local_dof_[k]); fixed_local_[dof])
      x[owned_rows_[k] - start] = fixed_value_local_[dof];
  SNEDE_PETSC(VecRestoreArray(u, &x));
}

bool DistributedStatic::every_dof_prescribed() const {
  std::int64_t fixed = 0;
  for (std::size_t k = 0; k < owned_rows_.size(); ++k) fixed += fixed_local_[static_cast<std::size_t>(owned_local_dof_[k])];
  std::int64_t total = 0;
  MPI_Allreduce(&fixed, &total, 1, MPI_INT64_T, MPI_SUM, part_.comm);
  return total == n_global_dofs();
}

double DistributedStatic::flops_per_residual() const {
  double local = static_cast<double>(body_.flops_per_element().force) * static_cast<double>(part_.local->n_cells());
  double total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, part_.comm);
  return total;
}

double DistributedStatic::external_force_norm() {
  double local = 0;
  for (double f : load_owned_) local += f * f;
  double total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, part_.comm);
  return std::sqrt(total);
}

double DistributedStatic::force_scale() {
  const std::vector<double>& p = part_.local->points();
  std::vector<double> low(dim_, std::numeric_limits<double>::infinity()), high(dim_, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < p.size(); ++i) {
    low[i % dim_] = std::min(low[i % dim_], p[i]);
    high[i % dim_] = std::min(high[i % dim_], -p[i]);  // −max, so one MIN reduction serves both
  }
  MPI_Allreduce(MPI_IN_PLACE, low.data(), dim_, MPI_DOUBLE, MPI_MIN, part_.comm);
  MPI_Allreduce(MPI_IN_PLACE, high.data(), dim_, MPI_DOUBLE, MPI_MIN, part_.comm);
  double diameter = 0;
  for (int k = 0; k < dim_; ++k) diameter += (-high[k] - low[k]) * (-high[k] - low[k]);
  return snede::force_scale(young_modulus(body_.material()), part_.local->cell_dim(), body_.thickness(),
                            std::sqrt(diameter));
}

void DistributedStatic::inverse_lumped_mass(Vec out) {
  const std::vector<double> mass = body_.lumped_mass();
  for (std::size_t i = 0; i < out_local_.size(); ++i) out_local_[i] = mass[i / static_cast<std::size_t>(dim_)];
  SNEDE_PETSC(VecZeroEntries(out));
  add_to_global(out_local_, out);
  PetscInt n = 0;
  PetscScalar* m = nullptr;
  SNEDE_PETSC(VecGetLocalSize(out, &n));
  SNEDE_PETSC(VecGetArray(out, &m));
  for (PetscInt i = 0; i < n; ++i) m[i] = m[i] > 0 ? 1 / m[i] : 0.0;
  SNEDE_PETSC(VecRestoreArray(out, &m));
}

double DistributedStatic::cfl_time_step() {
  double dt = snede::cfl_time_step(*part_.local, body_.material(), body_.density());
  MPI_Allreduce(MPI_IN_PLACE, &dt, 1, MPI_DOUBLE, MPI_MIN, part_.comm);
  return dt;
}

Mat DistributedStatic::assembled_tangent() {
  if (!assembled_)
    assembled_ = std::make_unique<DistributedAssembledTangent>(part_, body_, local_rows_, fixed_local_,
                                                               static_cast<PetscInt>(owned_rows_.size()));
  return assembled_->mat();
}

void DistributedStatic::assemble_tangent() {
  assembled_tangent();
  assembled_->assemble(u_linearization_);
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
                                     int max_iterations, const std::string& prefix, const std::string& criterion,
                                     double round_tolerance) {
  RankAgreement("DistributedStatic.solve")
      .input("method", method)
      .input("preconditioner", preconditioner)
      .input("rtol", rtol)
      .input("max_iterations", max_iterations)
      .input("options_prefix", prefix)
      .input("criterion", criterion)
      .input("round_tolerance", round_tolerance)
      .require(part_.comm);
  if (method != "cg" && method != "newton" && method != "ncg")
    throw std::invalid_argument("DistributedStatic.solve: method must be \"cg\", \"newton\" or \"ncg\", got \"" +
                                method + "\"");
  if (preconditioner != "none" && preconditioner != "jacobi" && preconditioner != "gamg" &&
      preconditioner != "bjacobi" && preconditioner != "sor" && preconditioner != "lu")
    throw std::invalid_argument(
        "DistributedStatic.solve: preconditioner must be \"none\", \"jacobi\", \"gamg\", \"bjacobi\", \"sor\" or "
        "\"lu\", got \"" + preconditioner + "\"");
  if (method == "ncg" && preconditioner != "none")
    throw std::invalid_argument("DistributedStatic.solve: nonlinear CG ('ncg') takes no preconditioner, got \"" +
                                preconditioner + "\"");
  if (!(rtol > 0) || !std::isfinite(rtol))
    throw std::invalid_argument("DistributedStatic.solve: rtol must be positive and finite, got " + std::to_string(rtol));
  if (criterion == "relative" && !(rtol < 1))
    throw std::invalid_argument("DistributedStatic.solve: a relative rtol must be below 1, got " + std::to_string(rtol));
  if (criterion != "relative" && criterion != "6.9" && criterion != "6.8")
    throw std::invalid_argument("DistributedStatic.solve: criterion must be \"relative\", \"6.9\" or \"6.8\", got \"" +
                                criterion + "\"");
  if (!(round_tolerance >= 0) || !std::isfinite(round_tolerance))
    throw std::invalid_argument("DistributedStatic.solve: round_tolerance must be ≥ 0 and finite");
  // The serial StaticSolver's rule: the criterion's, or (6.9) under PETSc's relative tests,
  // where it only decides whether the start is already in equilibrium (below).
  const StoppingRule rule{criterion == "relative" ? StoppingCriterion::with_reactions : stopping_criterion(criterion),
                          rtol, round_tolerance, force_scale(), static_cast<double>(n_global_dofs())};
  stopping_.reset();
  if (criterion != "relative") stopping_ = rule;
  stopping_external_norm_ = external_force_norm();
  const double start = wall_seconds();
  SolveResult result;
  const bool admissible_start = residual(u_, work_).admissible();
  result.initial_residual_norm = vec_norm(work_);
  stopping_reaction_norm_.reset();
  if (method == "cg") stopping_reaction_norm_ = last_reaction_norm_;
  // A start already in equilibrium by that rule is converged without an iteration, as
  // serially: the relative tests' ‖F‖ ≤ rtol ‖F(u₀)‖ is out of reach of a residual already at
  // round-off (Newton ended DIVERGED_LINE_SEARCH there, issue 38).
  const double equilibrium_tolerance = rule.tolerance(stopping_external_norm_, last_reaction_norm_);
  const bool at_equilibrium = admissible_start && result.initial_residual_norm <= equilibrium_tolerance;
  if (at_equilibrium) {
    result.converged = true;
    result.reason = method == "cg" ? "CONVERGED_ATOL" : "CONVERGED_FNORM_ABS";  // PETSc's, for a met absolute test
  } else {
    run_petsc(method, preconditioner, rtol, max_iterations, prefix, result);
  }
  // An inverted element or a non-finite state is never converged, and a rule is checked on
  // the final state (the factor allows CG's recursive residual to differ by round-off). The
  // relative tests stay PETSc's verdict: preconditioned CG measures another norm.
  const bool admissible = residual(u_, work_).admissible();
  result.residual_norm = vec_norm(work_);
  result.tolerance = at_equilibrium ? equilibrium_tolerance
                     : stopping_    ? stopping_tolerance()
                                    : rtol * result.initial_residual_norm;
  if (!admissible || !std::isfinite(result.residual_norm)) result.converged = false;
  if (result.converged && stopping_ && result.residual_norm > 2 * result.tolerance) {
    result.converged = false;
    result.reason = "DIVERGED_RESIDUAL_ABOVE_TOLERANCE (PETSc: " + result.reason + ")";
  }
  stopping_.reset();
  result.energy = energy();
  result.seconds = wall_seconds() - start;
  return result;
}

void DistributedStatic::run_petsc(const std::string& method, const std::string& preconditioner, double rtol,
                                  int max_iterations, const std::string& prefix, SolveResult& result) {
  SnesHandle snes;
  SNEDE_PETSC(SNESCreate(part_.comm, snes.out()));
  SNEDE_PETSC(SNESSetOptionsPrefix(snes, prefix.c_str()));
  SNEDE_PETSC(SNESSetFunction(snes, work_, residual_callback, this));
  // The shell needs no assembly: SNES's Jacobian step sets the linearisation point (and fills
  // GAMG's assembled copy). Nonlinear CG's line search takes K(x)d from it too.
  // none and Jacobi need no matrix; GAMG, block Jacobi (ILU(0) on each rank's block), SOR
  // (symmetric sweeps over each rank's rows, PETSc's default on MPIAIJ) and LU (MUMPS, the
  // parallel direct solver in Debian's PETSc) take the assembled one.
  const bool assembled = preconditioner != "none" && preconditioner != "jacobi";
  SNEDE_PETSC(SNESSetJacobian(snes, tangent_, assembled ? assembled_tangent() : tangent_.get(), jacobian_callback, this));
  KSP ksp = nullptr;
  PC pc = nullptr;
  SNEDE_PETSC(SNESGetKSP(snes, &ksp));
  SNEDE_PETSC(KSPSetType(ksp, KSPCG));
  SNEDE_PETSC(KSPGetPC(ksp, &pc));
  SNEDE_PETSC(PCSetType(pc, preconditioner.c_str()));  // PETSc's names
  if (preconditioner == "lu") SNEDE_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  // PETSc's relative tolerance (< 1), or its default when a rule (whose rtol may be ≥ 1) stops.
  const double relative = stopping_ ? PETSC_DEFAULT : rtol;
  if (method == "cg") {
    SNEDE_PETSC(SNESSetType(snes, SNESKSPONLY));
    SNEDE_PETSC(KSPSetTolerances(ksp, relative, 0.0, PETSC_DEFAULT, max_iterations));
  } else if (method == "newton") {
    SNEDE_PETSC(SNESSetType(snes, SNESNEWTONLS));
    SNEDE_PETSC(SNESSetTolerances(snes, 0.0, relative, 0.0, max_iterations, PETSC_DEFAULT));
  } else {
    register_line_searches();
    SNEDE_PETSC(SNESSetType(snes, SNESNCG));
    SNEDE_PETSC(SNESNCGSetType(snes, SNES_NCG_PRP));
    SNESLineSearch line_search = nullptr;
    SNEDE_PETSC(SNESGetLineSearch(snes, &line_search));
    SNEDE_PETSC(SNESLineSearchSetType(line_search, "snede_secant"));
    SNEDE_PETSC(SNESSetTolerances(snes, 0.0, relative, 0.0, max_iterations, PETSC_DEFAULT));
  }
  if (stopping_) {
    SNEDE_PETSC(SNESSetConvergenceTest(snes, snes_rule_callback, this, nullptr));
    if (method == "cg") {
      SNEDE_PETSC(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED));
      SNEDE_PETSC(KSPSetConvergenceTest(ksp, ksp_rule_callback, this, nullptr));
    }
  }
  SNEDE_PETSC(SNESSetFromOptions(snes));
  solve_through(ksp, [&] { SNEDE_PETSC(SNESSolve(snes, nullptr, u_)); });
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
}

double DistributedStatic::energy(Vec u) {
  to_local(u, u_local_);
  EvaluationReport report;
  double local = body_.energy(u_local_, report);
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(u, &start, &end));
  const PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArrayRead(u, &x));
  for (std::size_t k = 0; k < owned_rows_.size(); ++k) local -= load_owned_[k] * x[owned_rows_[k] - start];
  SNEDE_PETSC(VecRestoreArrayRead(u, &x));
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
