#include "solve/model.hpp"

#include <cmath>
#include <limits>
#include <numeric>

#include "core/error.hpp"

namespace snede {
namespace {

// Read-only and writable views of a sequential Vec as spans (RAII restore).
class ReadView {
 public:
  explicit ReadView(Vec v) : v_(v) {
    SNEDE_PETSC(VecGetArrayRead(v_, &data_));
    SNEDE_PETSC(VecGetLocalSize(v_, &n_));
  }
  ~ReadView() { VecRestoreArrayRead(v_, &data_); }
  std::span<const double> span() const { return {data_, static_cast<std::size_t>(n_)}; }

 private:
  Vec v_;
  const PetscScalar* data_ = nullptr;
  PetscInt n_ = 0;
};

class WriteView {
 public:
  explicit WriteView(Vec v) : v_(v) {
    SNEDE_PETSC(VecGetArray(v_, &data_));
    SNEDE_PETSC(VecGetLocalSize(v_, &n_));
  }
  ~WriteView() { VecRestoreArray(v_, &data_); }
  std::span<double> span() const { return {data_, static_cast<std::size_t>(n_)}; }

 private:
  Vec v_;
  PetscScalar* data_ = nullptr;
  PetscInt n_ = 0;
};

}  // namespace

Model::Model(ElasticBody& body) : body_(body), constraints_(body.dim()) {
  n_points_ = body_.mesh().n_points();
  constraints_.resize(n_points_);
  nodal_forces_.assign(body_.n_dofs(), 0.0);
  create_vectors();
  body_.mesh().connectivity().add_watcher(this);
}

Model::~Model() {
  body_.mesh().connectivity().remove_watcher(this);
  VecDestroy(&u_);
  VecDestroy(&u_linearization_);
  MatDestroy(&tangent_);
}

void Model::create_vectors() {
  const PetscInt n = n_dofs();
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, n, &u_));
  SNEDE_PETSC(VecSetBlockSize(u_, dim()));
  SNEDE_PETSC(VecDuplicate(u_, &u_linearization_));
  SNEDE_PETSC(MatCreateShell(PETSC_COMM_SELF, n, n, n, n, this, &tangent_));
  SNEDE_PETSC(MatShellSetOperation(tangent_, MATOP_MULT, reinterpret_cast<void (*)(void)>(tangent_mult_callback)));
  SNEDE_PETSC(MatSetOption(tangent_, MAT_SYMMETRIC, PETSC_TRUE));
  SNEDE_PETSC(MatSetOption(tangent_, MAT_SPD, PETSC_TRUE));
}

void Model::fix(std::span<const VertexId> vertices, std::span<const double> values) {
  constraints_.fix(vertices, values);
  enforce_constraints(u_);
}

void Model::slide(std::span<const VertexId> vertices, std::span<const double> direction) {
  ReadView u(u_);
  constraints_.slide(vertices, direction, u.span());
}

void Model::set_gravity(std::span<const double> g) {
  if (g.size() != static_cast<std::size_t>(dim()))
    throw std::invalid_argument("gravity must have " + std::to_string(dim()) + " components");
  gravity_.assign(g.begin(), g.end());
  external_valid_ = false;
}

void Model::add_nodal_force(std::span<const VertexId> vertices, std::span<const double> forces) {
  const bool one_for_all = forces.size() == static_cast<std::size_t>(dim());
  if (!one_for_all && forces.size() != vertices.size() * dim())
    throw std::invalid_argument("force must be one vector of " + std::to_string(dim()) +
                                " components or one per vertex");
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (vertices[i] < 0 || vertices[i] >= n_points_)
      throw std::invalid_argument("vertex " + std::to_string(vertices[i]) + " does not exist");
    for (int k = 0; k < dim(); ++k) {
      const double value = forces[(one_for_all ? 0 : i * dim()) + k];
      if (!std::isfinite(value)) throw std::invalid_argument("non-finite force on vertex " + std::to_string(vertices[i]));
      nodal_forces_[static_cast<std::size_t>(vertices[i]) * dim() + k] += value;
    }
  }
  external_valid_ = false;
}

void Model::clear_loads() {
  gravity_.clear();
  std::fill(nodal_forces_.begin(), nodal_forces_.end(), 0.0);
  external_valid_ = false;
}

const std::vector<double>& Model::external_forces() {
  if (!external_valid_) {
    external_ = nodal_forces_;
    if (!gravity_.empty()) {
      const std::vector<double> g = body_.gravity_forces(gravity_);
      for (std::size_t i = 0; i < g.size(); ++i) external_[i] += g[i];
    }
    external_valid_ = true;
  }
  return external_;
}

void Model::set_linearization_point(Vec u) { SNEDE_PETSC(VecCopy(u, u_linearization_)); }

double Model::potential_energy(Vec u, EvaluationReport& report) {
  ReadView x(u);
  const double internal = body_.energy(x.span(), report);
  const std::vector<double>& f = external_forces();
  return internal - std::inner_product(f.begin(), f.end(), x.span().begin(), 0.0);
}

void Model::residual(Vec u, Vec F, EvaluationReport& report) {
  ReadView x(u);
  WriteView r(F);
  body_.internal_forces(x.span(), r.span(), report);
  const std::vector<double>& f = external_forces();
  std::vector<double> reaction(r.span().size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    r.span()[i] = -r.span()[i] - f[i];  // ∇Π = −f_int − f_ext
    reaction[i] = r.span()[i];
  }
  constraints_.project_complement(reaction);
  last_reaction_norm_ = std::sqrt(std::inner_product(reaction.begin(), reaction.end(), reaction.begin(), 0.0));
  constraints_.project(r.span());
  // (I − P)(u − anchor): zero while the constraints hold; pulls them back otherwise.
  std::vector<double> offset(x.span().begin(), x.span().end());
  std::vector<double> held = offset;
  constraints_.enforce(held);
  for (std::size_t i = 0; i < offset.size(); ++i) r.span()[i] += offset[i] - held[i];
}

void Model::reaction_forces(Vec u, Vec R) {
  EvaluationReport report;
  {
    ReadView x(u);
    WriteView r(R);
    body_.internal_forces(x.span(), r.span(), report);
    const std::vector<double>& f = external_forces();
    for (std::size_t i = 0; i < f.size(); ++i) r.span()[i] = -r.span()[i] - f[i];
    constraints_.project_complement(r.span());
  }
  throw_if_domain_error(report);
}

void Model::enforce_constraints(Vec u) const {
  WriteView x(u);
  constraints_.enforce(x.span());
}

double Model::force_scale() const {
  const std::vector<double>& p = body_.mesh().points();
  std::vector<double> lo(dim(), std::numeric_limits<double>::infinity()), hi(dim(), -std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < p.size(); ++i) {
    lo[i % dim()] = std::min(lo[i % dim()], p[i]);
    hi[i % dim()] = std::max(hi[i % dim()], p[i]);
  }
  double diameter = 0;
  for (int k = 0; k < dim(); ++k) diameter += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  diameter = std::sqrt(diameter);
  const double E = young_modulus(body_.material());
  return dim() == 3 ? E * diameter * diameter : E * body_.thickness() * diameter;
}

bool Model::admissible(Vec u, std::string* why) const {
  PetscReal norm = 0;
  SNEDE_PETSC(VecNorm(u, NORM_2, &norm));
  if (!std::isfinite(norm)) {
    if (why) *why = "DIVERGED_NONFINITE_STATE";
    return false;
  }
  if (forbids_inversion(body_.material())) {
    ReadView x(u);
    if (!body_.inverted_elements(x.span()).empty()) {
      if (why) *why = "DIVERGED_INVERTED_ELEMENTS";
      return false;
    }
  }
  return true;
}

void Model::tangent_mult(Vec d, Vec out) {
  ReadView x(u_linearization_);
  ReadView direction(d);
  WriteView result(out);
  std::vector<double> projected(direction.span().begin(), direction.span().end());
  constraints_.project(projected);
  EvaluationReport report;
  body_.tangent_apply(x.span(), projected, result.span(), report);
  constraints_.project(result.span());
  // + (I − P) d
  std::vector<double> complement(direction.span().begin(), direction.span().end());
  constraints_.project_complement(complement);
  for (std::size_t i = 0; i < complement.size(); ++i) result.span()[i] += complement[i];
  throw_if_domain_error(report);
}

PetscErrorCode Model::tangent_mult_callback(Mat A, Vec d, Vec out) {
  return petsc_callback("snede tangent shell MatMult", [&] {
    void* context = nullptr;
    SNEDE_PETSC(MatShellGetContext(A, &context));
    static_cast<Model*>(context)->tangent_mult(d, out);
  });
}

std::vector<double> Model::carried_over(std::span<const double> old_values, VertexId n_old_points) const {
  const VertexId n = body_.mesh().n_points();
  std::vector<double> values(static_cast<std::size_t>(n) * dim(), 0.0);
  std::copy(old_values.begin(), old_values.begin() + static_cast<std::size_t>(std::min(n, n_old_points)) * dim(),
            values.begin());
  for (VertexId v = n_old_points; v < n; ++v) {
    const VertexParents parents = body_.mesh().parents(v);
    for (int i = 0; i < parents.count; ++i)
      for (int k = 0; k < dim(); ++k)
        values[static_cast<std::size_t>(v) * dim() + k] +=
            parents.weight[i] * values[static_cast<std::size_t>(parents.vertex[i]) * dim() + k];
  }
  return values;
}

void Model::on_change(const Connectivity&, const ConnectivityChange&) {
  external_valid_ = false;  // gravity follows the element masses
  const VertexId n_new = body_.mesh().n_points();
  if (n_new == n_points_) return;
  // Sizes change: carry the state over, then reissue vectors and the shell.
  std::vector<double> u_old;
  {
    ReadView u(u_);
    u_old.assign(u.span().begin(), u.span().end());
  }
  const std::vector<double> u_new = carried_over(u_old, n_points_);
  std::vector<double> forces = nodal_forces_;
  forces.resize(static_cast<std::size_t>(n_new) * dim(), 0.0);  // loads are not inherited
  nodal_forces_ = std::move(forces);
  for (VertexId v = n_points_; v < n_new; ++v) constraints_.inherit(v, body_.mesh().parents(v));
  VecDestroy(&u_);
  VecDestroy(&u_linearization_);
  MatDestroy(&tangent_);
  n_points_ = n_new;
  create_vectors();
  {
    WriteView u(u_);
    std::copy(u_new.begin(), u_new.end(), u.span().begin());
  }
  ++generation_;
}

}  // namespace snede
