#include "problem/distributed_static.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
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
#include "problem/projected_stiffness.hpp"
#include "problem/rank_piece_holding.hpp"
#include "problem/stopping.hpp"

namespace snede {
namespace {

void check_conditions(const DistributedConditions& c, int dim, std::int64_t n_vertices) {
  // `what` names the ids, `values_name` their values (the ids' name when empty).
  const auto check = [&](const std::vector<std::int64_t>& ids, std::size_t values, const char* what,
                         std::string values_name = {}) {
    if (values_name.empty()) values_name = what;
    if (values != ids.size() * static_cast<std::size_t>(dim))
      throw std::invalid_argument("DistributedStatic: " + values_name + " needs " + std::to_string(dim) +
                                  " values per vertex: " + std::to_string(ids.size()) + " vertices, " +
                                  std::to_string(values) + " values");
    for (std::int64_t v : ids)
      if (v < 0 || v >= n_vertices)
        throw std::invalid_argument(std::string("DistributedStatic: ") + what + " vertex " + std::to_string(v) +
                                    " is not a vertex of the serial mesh (0.." + std::to_string(n_vertices - 1) + ")");
  };
  check(c.fixed, c.fixed_values.size(), "fixed");
  check(c.sliding, c.sliding_directions.size(), "sliding", "sliding_directions");
  check(c.sliding, c.sliding_anchors.size(), "sliding", "sliding_anchors");
  check(c.loaded, c.forces.size(), "loaded");
  // What Constraints::fix and ::slide would refuse, refused here on every rank alike (a rank
  // holds only its vertices' constraints).
  const auto vertex_values = [&](const std::vector<double>& values, std::size_t k) {
    return std::span<const double>(values).subspan(k * dim, dim);
  };
  const auto finite = [](std::span<const double> x) {
    return std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
  };
  std::unordered_map<std::int64_t, std::size_t> fixed_entry;
  for (std::size_t k = 0; k < c.fixed.size(); ++k) {
    const std::string vertex = " vertex " + std::to_string(c.fixed[k]);
    if (!finite(vertex_values(c.fixed_values, k)))
      throw std::invalid_argument("DistributedStatic: fixed_values of" + vertex + " are not finite");
    const auto [first, new_vertex] = fixed_entry.try_emplace(c.fixed[k], k);
    const auto earlier = vertex_values(c.fixed_values, first->second), these = vertex_values(c.fixed_values, k);
    if (!new_vertex && !std::equal(earlier.begin(), earlier.end(), these.begin()))
      throw std::invalid_argument("DistributedStatic: fixed" + vertex + " is listed twice (entries " +
                                  std::to_string(first->second) + " and " + std::to_string(k) + ") with different values");
  }
  std::unordered_map<std::int64_t, std::size_t> sliding_entry;
  for (std::size_t k = 0; k < c.sliding.size(); ++k) {
    const std::string vertex = " vertex " + std::to_string(c.sliding[k]);
    const auto direction = vertex_values(c.sliding_directions, k);
    const double norm = std::sqrt(std::inner_product(direction.begin(), direction.end(), direction.begin(), 0.0));
    if (!(norm > 0 && std::isfinite(norm)))
      throw std::invalid_argument("DistributedStatic: sliding" + vertex + "'s direction must be non-zero and finite");
    if (!finite(vertex_values(c.sliding_anchors, k)))
      throw std::invalid_argument("DistributedStatic: sliding_anchors of" + vertex + " are not finite");
    if (fixed_entry.count(c.sliding[k]))
      throw std::invalid_argument("DistributedStatic: vertex " + std::to_string(c.sliding[k]) +
                                  " is both fixed and sliding; a vertex has one constraint");
    if (const auto [first, new_vertex] = sliding_entry.try_emplace(c.sliding[k], k); !new_vertex)
      throw std::invalid_argument("DistributedStatic: sliding" + vertex + " is listed twice (entries " +
                                  std::to_string(first->second) + " and " + std::to_string(k) + ")");
  }
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
      .input("sliding", c.sliding)
      .input("sliding_directions", c.sliding_directions)
      .input("sliding_anchors", c.sliding_anchors)
      .input("forces", InputDigest().add(c.loaded).add(c.forces))
      .input("gravity", c.gravity)
      .require(comm);
  return true;
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
      dim_(part.local->dim()),
      constraints_(dim_),
      owned_constraints_(dim_) {
  check_conditions(conditions, dim_, part.n_global_vertices);
  const MPI_Comm comm = part.comm;
  const std::size_t n_local = static_cast<std::size_t>(part.local->n_points());
  const std::size_t n_dofs = n_local * static_cast<std::size_t>(dim_);
  std::unordered_map<std::int64_t, std::size_t> local_of;
  for (std::size_t v = 0; v < n_local; ++v) local_of[part.global_vertex[v]] = v;

  // The serial Constraints of the rank's vertices, set as Body.fix and Body.slide set them.
  constraints_.resize(static_cast<VertexId>(n_local));
  std::vector<VertexId> fixed;
  std::vector<double> fixed_values;
  for (std::size_t k = 0; k < conditions.fixed.size(); ++k)
    if (const auto found = local_of.find(conditions.fixed[k]); found != local_of.end()) {
      fixed.push_back(static_cast<VertexId>(found->second));
      fixed_values.insert(fixed_values.end(), conditions.fixed_values.begin() + k * dim_,
                          conditions.fixed_values.begin() + (k + 1) * dim_);
    }
  constraints_.fix(fixed, fixed_values);
  std::vector<double> sliding_anchors(n_dofs, 0.0);
  for (std::size_t k = 0; k < conditions.sliding.size(); ++k)
    if (const auto found = local_of.find(conditions.sliding[k]); found != local_of.end()) {
      const auto v = static_cast<VertexId>(found->second);
      std::copy_n(conditions.sliding_anchors.begin() + k * dim_, dim_, sliding_anchors.begin() + v * dim_);
      constraints_.slide(std::span(&v, 1), std::span(conditions.sliding_directions).subspan(k * dim_, dim_),
                         sliding_anchors);
    }
  projection_ = projection_blocks(constraints_, constraints_.n_points());
  // c of the serial Model from the whole body's cells (a cell lives on one rank).
  double volume = volume_of_cells(*part.local);
  MPI_Allreduce(MPI_IN_PLACE, &volume, 1, MPI_DOUBLE, MPI_SUM, comm);
  constraint_stiffness_ = snede::constraint_stiffness(body_.material(), part.local->cell_dim(), body_.thickness(), volume,
                                                      static_cast<double>(part.n_global_cells));
  complement_ = complement_blocks(projection_, dim_);
  for (double& x : complement_) x *= constraint_stiffness_;  // c (I − P)
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
  owned_constraints_.resize(static_cast<VertexId>(n_owned));
  for (std::size_t v = 0; v < n_local; ++v)
    if (part.owned[v]) {
      owned_constraints_.assign(static_cast<VertexId>((rows[v * dim_] - start) / dim_), constraints_[static_cast<VertexId>(v)]);
      for (int d = 0; d < dim_; ++d) {
        const PetscInt row = rows[v * dim_ + d];
        if (row < start || row >= end)
          throw std::logic_error("DistributedStatic: PETSc's vertex numbering does not match the vector's layout");
        owned_rows_.push_back(row);
        owned_local_dof_.push_back(static_cast<PetscInt>(v * dim_ + d));
        load_owned_.push_back(load_local[v * dim_ + d]);
      }
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
  assign_owned([&](std::size_t dof) {
    const auto vertex = static_cast<std::size_t>(part_.global_vertex[dof / dim_]);
    return serial.empty() ? 0.0 : serial[vertex * dim_ + dof % dim_];
  });
}

void DistributedStatic::set_local_displacement(std::span<const double> local) {
  const std::size_t expected = static_cast<std::size_t>(part_.local->n_points()) * dim_;
  bool fits = local.size() == expected;
  for (std::size_t k = 0; fits && k < local.size(); ++k) fits = std::isfinite(local[k]);
  // Each rank checks its own array; all raise if one does, so none waits in a later collective.
  int all_fit = fits;
  MPI_Allreduce(MPI_IN_PLACE, &all_fit, 1, MPI_INT, MPI_MIN, part_.comm);
  if (!all_fit) {
    const std::string mine = fits ? "another rank's did not"
                                  : "this rank gave " + std::to_string(local.size()) + " values for " +
                                        std::to_string(expected) + " (or a non-finite one)";
    throw std::invalid_argument("DistributedStatic.set_local_displacement: every rank must give (n_local_vertices × "
                                "dim) finite values for its part; " + mine);
  }
  assign_owned([&](std::size_t dof) { return local[dof]; });
}

template <class ValueOfLocalDof>
void DistributedStatic::assign_owned(ValueOfLocalDof value) {
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(u_, &start, &end));
  {
    const WriteView u(u_);
    for (std::size_t k = 0; k < owned_rows_.size(); ++k)
      u.span()[owned_rows_[k] - start] = value(static_cast<std::size_t>(owned_local_dof_[k]));
  }
  enforce_constraints(u_);
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
  // F = P(−f_int(u) − f_ext) + c (I − P)(u − ū); the fixed rows' −f_int − f_ext are the reactions.
  to_local(u, u_local_);
  EvaluationReport report;
  std::vector<double> f(u_local_.size(), 0.0);
  body_.internal_forces(u_local_, f, report);
  for (double& x : f) x = -x;
  SNEDE_PETSC(VecZeroEntries(F));
  add_to_global(f, F);
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(F, &start, &end));
  const WriteView F_view(F);
  const ReadView u_view(u);
  const std::span<double> r = F_view.span();
  for (std::size_t k = 0; k < owned_rows_.size(); ++k) r[owned_rows_[k] - start] -= load_owned_[k];
  // The reactions (I − P)(−f_int − f_ext), then r = P(−f_int − f_ext) + c (I − P)(u − ū), as the
  // serial Model has it.
  std::vector<double> reaction(r.begin(), r.end());
  owned_constraints_.project_complement(reaction);
  owned_constraints_.project(r);
  std::vector<double> held(u_view.span().begin(), u_view.span().end());
  owned_constraints_.enforce(held);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] += constraint_stiffness_ * (u_view.span()[i] - held[i]);
  const bool inverted = !report.inverted.empty() && forbids_inversion(body_.material());
  // Ranks with an inverted element, ranks with a non-finite one, ‖reactions‖².
  double sums[3] = {inverted ? 1.0 : 0.0, report.domain_errors.empty() ? 0.0 : 1.0,
                    std::inner_product(reaction.begin(), reaction.end(), reaction.begin(), 0.0)};
  MPI_Allreduce(MPI_IN_PLACE, sums, 3, MPI_DOUBLE, MPI_SUM, part_.comm);
  last_reaction_norm_ = std::sqrt(sums[2]);
  last_failure_ = sums[1] > 0 ? "DIVERGED_NONFINITE_STATE" : sums[0] > 0 ? "DIVERGED_INVERTED_ELEMENTS" : "";
  const ResidualCheck check{sums[1] == 0, sums[0] > 0};
  // A failure on any rank makes the residual NaN everywhere: no solver can call it converged.
  if (!check.admissible()) std::fill(r.begin(), r.end(), std::numeric_limits<double>::quiet_NaN());
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

void DistributedStatic::enforce_constraints(Vec u) { owned_constraints_.enforce(WriteView(u).span()); }

void DistributedStatic::project_onto_allowed_motions(Vec v) { owned_constraints_.project(WriteView(v).span()); }

bool DistributedStatic::every_dof_prescribed() const {
  auto constrained = static_cast<std::int64_t>(owned_constraints_.n_constrained_components());
  std::int64_t total = 0;
  MPI_Allreduce(&constrained, &total, 1, MPI_INT64_T, MPI_SUM, part_.comm);
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

// The MPIAIJ tangent at a state, scaled like the shell.
class AssembledDistributedTangent final : public AssembledProblemTangent {
 public:
  explicit AssembledDistributedTangent(DistributedStatic& problem)
      : problem_(problem),
        tangent_(problem.part_, problem.body_, problem.local_rows_, std::span<const double>(problem.projection_),
                 static_cast<PetscInt>(problem.owned_rows_.size()), problem.constraint_stiffness_),
        u_local_(problem.u_local_.size()) {}
  Mat mat() const override { return tangent_.mat(); }
  void assemble(Vec u) override {
    problem_.to_local(u, u_local_);
    tangent_.assemble(u_local_);
    if (problem_.operator_scale_ != 1) SNEDE_PETSC(MatScale(tangent_.mat(), problem_.operator_scale_));
  }
  bool matches() const override { return true; }  // a distributed mesh is not edited

 private:
  DistributedStatic& problem_;
  DistributedAssembledTangent tangent_;
  std::vector<double> u_local_;
};

void DistributedStatic::require_held() const { require_held_on_ranks(part_, constraints_); }

RankPieces DistributedStatic::pieces() const { return pieces_on_ranks(part_, constraints_); }

std::unique_ptr<AssembledProblemTangent> DistributedStatic::make_assembled_tangent(MatrixFormat) {
  return std::make_unique<AssembledDistributedTangent>(*this);
}

void DistributedStatic::tangent_mult(Vec d, Vec out) {
  // (P K P + c (I − P)) d, K at the linearisation point.
  to_local(d, d_local_);
  constraints_.project(d_local_);
  std::fill(out_local_.begin(), out_local_.end(), 0.0);
  EvaluationReport report;
  body_.tangent_apply(u_linearization_, d_local_, out_local_, report);
  SNEDE_PETSC(VecZeroEntries(out));
  add_to_global(out_local_, out);
  {
    // P is vertex by vertex: projecting the owners' sums is projecting every rank's share.
    const WriteView y(out);
    owned_constraints_.project(y.span());
    owned_constraints_.add_complement(ReadView(d).span(), y.span(), constraint_stiffness_);
  }
  if (operator_scale_ != 1) SNEDE_PETSC(VecScale(out, operator_scale_));
}

void DistributedStatic::tangent_diagonal(Vec diagonal) {
  // diag(P K P + c (I − P)): the projected element stiffnesses' diagonals on this rank's cells
  // and the owned vertices' diag(c (I − P)) (c on a fixed dof, for PCJACOBI), the ghosts' shares
  // added into their owners.
  std::fill(out_local_.begin(), out_local_.end(), 0.0);
  const auto d = static_cast<std::size_t>(dim_);
  for_each_projected_element_matrix(body_, u_linearization_, projection_, [&](ElementId, std::span<const VertexId> vertices,
                                                                              std::span<const double> K) {
    const std::size_t n = vertices.size() * d;
    for (std::size_t row = 0; row < n; ++row)
      out_local_[static_cast<std::size_t>(vertices[row / d]) * d + row % d] += K[row * n + row];
  });
  for (std::size_t dof = 0; dof < out_local_.size(); ++dof)
    if (part_.owned[dof / d]) out_local_[dof] += complement_[dof * d + dof % d];
  SNEDE_PETSC(VecZeroEntries(diagonal));
  add_to_global(out_local_, diagonal);
  if (operator_scale_ != 1) SNEDE_PETSC(VecScale(diagonal, operator_scale_));
}

double DistributedStatic::energy(Vec u) {
  to_local(u, u_local_);
  EvaluationReport report;
  double local = body_.energy(u_local_, report);
  // NaN on a rank with a non-finite element (which the kernels skip) makes the sum NaN.
  if (!report.domain_errors.empty()) local = std::numeric_limits<double>::quiet_NaN();
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

std::vector<double> DistributedStatic::local_displacement() {
  std::vector<double> u(u_local_.size());
  to_local(u_, u);
  return u;
}

}  // namespace snede
