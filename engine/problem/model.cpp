#include "problem/model.hpp"

#include <petsc/private/petscimpl.h>  // PetscObjectStateGet: a Vec's write count

#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "core/growable_vec.hpp"
#include "core/norms.hpp"
#include "core/petsc_util.hpp"
#include "core/predicates.hpp"
#include "problem/projected_stiffness.hpp"
#include "problem/stopping.hpp"
#include "problem/tangent_assembly.hpp"

namespace snede {

Model::Model(ElasticBody& body) : body_(body), constraints_(body.dim()) {
  n_points_ = body_.mesh().n_points();
  constraints_.resize(n_points_);
  create_vectors();
  body_.mesh().connectivity().add_watcher(this);
}

Model::~Model() {
  body_.mesh().connectivity().remove_watcher(this);
  if (tangent_) MatShellSetContext(tangent_, nullptr);  // a petsc4py handle may outlive the model
}

void Model::create_vectors() {
  create_growable_vec(n_dofs(), dim(), u_.out());
  create_growable_vec(n_dofs(), dim(), u_linearization_.out());
  create_tangent();
}

void Model::create_tangent() {
  const PetscInt n = n_dofs();
  SNEDE_PETSC(MatCreateShell(PETSC_COMM_SELF, n, n, n, n, this, tangent_.out()));
  SNEDE_PETSC(MatShellSetOperation(tangent_, MATOP_MULT, reinterpret_cast<void (*)(void)>(tangent_mult_callback)));
  SNEDE_PETSC(MatShellSetOperation(tangent_, MATOP_GET_DIAGONAL,
                                   reinterpret_cast<void (*)(void)>(tangent_diagonal_callback)));
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
  for (double x : g)
    if (!std::isfinite(x)) throw std::invalid_argument("gravity must be finite, got " + std::to_string(x));
  gravity_.assign(g.begin(), g.end());
  loads_changed();
}

void Model::clear_gravity() {
  gravity_.clear();
  loads_changed();
}

std::vector<double>& Model::channel(const std::string& name) {
  if (name.empty()) throw std::invalid_argument("a load channel needs a name");
  auto [it, created] = channels_.try_emplace(name);
  if (created) it->second.assign(body_.n_dofs(), 0.0);
  return it->second;
}

void Model::add_nodal_force(const std::string& name, std::span<const VertexId> vertices,
                            std::span<const double> forces) {
  const bool one_for_all = forces.size() == static_cast<std::size_t>(dim());
  if (!one_for_all && forces.size() != vertices.size() * dim())
    throw std::invalid_argument("force must be one vector of " + std::to_string(dim()) +
                                " components or one per vertex");
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (!body_.mesh().is_vertex(vertices[i]))
      throw std::invalid_argument("vertex " + std::to_string(vertices[i]) + " does not exist");
    for (int k = 0; k < dim(); ++k)
      if (!std::isfinite(forces[(one_for_all ? 0 : i * dim()) + k]))
        throw std::invalid_argument("non-finite force on vertex " + std::to_string(vertices[i]));
  }
  std::vector<double>& f = channel(name);
  for (std::size_t i = 0; i < vertices.size(); ++i)
    for (int k = 0; k < dim(); ++k)
      f[static_cast<std::size_t>(vertices[i]) * dim() + k] += forces[(one_for_all ? 0 : i * dim()) + k];
  loads_changed();
}

void Model::set_nodal_forces(const std::string& name, std::span<const VertexId> vertices,
                             std::span<const double> forces) {
  clear_channel(name);
  add_nodal_force(name, vertices, forces);
}

void Model::clear_channel(const std::string& name) {
  channels_.erase(name);
  loads_changed();
}

void Model::clear_loads() {
  gravity_.clear();
  channels_.clear();
  loads_changed();
}

std::vector<std::string> Model::load_channels() const {
  std::vector<std::string> names;
  for (const auto& entry : channels_) names.push_back(entry.first);
  return names;
}

std::vector<double> Model::channel_forces(const std::string& name) const {
  const auto it = channels_.find(name);
  return it == channels_.end() ? std::vector<double>(body_.n_dofs(), 0.0) : it->second;
}

void Model::add_carried_field(Vec* field) { carried_fields_.push_back(field); }

void Model::remove_carried_field(Vec* field) { std::erase(carried_fields_, field); }

const std::vector<double>& Model::external_forces() {
  if (!external_valid_) {
    external_.assign(body_.n_dofs(), 0.0);
    for (const auto& entry : channels_)
      for (std::size_t i = 0; i < external_.size(); ++i) external_[i] += entry.second[i];
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

void Model::loads_changed() {
  external_valid_ = false;
  gradient_.valid = false;
}

Model::GradientKey Model::key_of(Vec u) {
  GradientKey key;
  SNEDE_PETSC(PetscObjectGetId(reinterpret_cast<PetscObject>(u), &key.vec));
  SNEDE_PETSC(PetscObjectStateGet(reinterpret_cast<PetscObject>(u), &key.state));
  return key;
}

void Model::residual(Vec u, Vec F, EvaluationReport& report) {
  const std::size_t errors_before = report.domain_errors.size();
  {
    ReadView x(u);
    WriteView r(F);
    body_.internal_forces(x.span(), r.span(), report);
    const std::vector<double>& f = external_forces();
    gradient_.values.resize(r.span().size());
    for (std::size_t i = 0; i < f.size(); ++i) {
      r.span()[i] = -r.span()[i] - f[i];  // ∇Π = −f_int − f_ext
      gradient_.values[i] = r.span()[i];
    }
    std::vector<double> reaction = gradient_.values;
    constraints_.project_complement(reaction);
    last_reaction_norm_ = euclidean_norm(reaction);
    constraints_.project(r.span());
    // c (I − P)(u − anchor): zero while the constraints hold; pulls them back otherwise.
    std::vector<double> offset(x.span().begin(), x.span().end());
    std::vector<double> held = offset;
    constraints_.enforce(held);
    const double c = constraint_stiffness();
    for (std::size_t i = 0; i < offset.size(); ++i) r.span()[i] += c * (offset[i] - held[i]);
  }
  gradient_.valid = report.domain_errors.size() == errors_before;
  gradient_.key = key_of(u);
}

std::vector<double> Model::potential_gradient(Vec u) {
  if (gradient_.valid && gradient_.key == key_of(u)) return gradient_.values;
  EvaluationReport report;
  std::vector<double> g(body_.n_dofs());
  {
    ReadView x(u);
    body_.internal_forces(x.span(), g, report);
  }
  throw_if_domain_error(report);
  const std::vector<double>& f = external_forces();
  for (std::size_t i = 0; i < f.size(); ++i) g[i] = -g[i] - f[i];
  return g;
}

void Model::reaction_forces(Vec u, Vec R) {
  std::vector<double> g = potential_gradient(u);
  constraints_.project_complement(g);
  set_vec_values(R, g);
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
  return snede::force_scale(young_modulus(body_.material()), body_.mesh().cell_dim(), body_.thickness(), diameter);
}

double Model::constraint_stiffness() const {
  if (constraint_stiffness_ == 0) {
    const Mesh& mesh = body_.mesh();
    constraint_stiffness_ = snede::constraint_stiffness(body_.material(), mesh.cell_dim(), body_.thickness(),
                                                        volume_of_cells(mesh), static_cast<double>(mesh.n_cells()));
  }
  return constraint_stiffness_;
}

bool Model::admissible(Vec u, std::string* why, double det_floor) const {
  PetscReal norm = 0;
  SNEDE_PETSC(VecNorm(u, NORM_2, &norm));
  if (!std::isfinite(norm)) {
    if (why) *why = "DIVERGED_NONFINITE_STATE";
    return false;
  }
  if (forbids_inversion(body_.material())) {
    ReadView x(u);
    if (!body_.inverted_elements(x.span(), det_floor).empty()) {
      if (why) *why = "DIVERGED_INVERTED_ELEMENTS";
      return false;
    }
  }
  return true;
}

std::string Model::refuses(const Simplex& cell) const {
  if (!forbids_inversion(body_.material())) return {};
  const Mesh& mesh = body_.mesh();
  const int space = mesh.space_dim(), corners = cell.count();
  const ReadView u(u_);
  std::array<std::array<double, 3>, max_dimension + 1> x{};
  const auto vertices = cell.oriented_vertices();
  for (int i = 0; i < corners; ++i)
    for (int k = 0; k < space; ++k)
      x[i][k] = mesh.point(vertices[i])[k] + u.span()[static_cast<std::size_t>(vertices[i]) * space + k];
  const bool inverted = mesh.is_surface() ? collinear_3d(x[0].data(), x[1].data(), x[2].data())
                        : space == 2      ? orientation_2d(x[0].data(), x[1].data(), x[2].data()) <= 0
                                          : orientation_3d(x[0].data(), x[1].data(), x[2].data(), x[3].data()) <= 0;
  return inverted ? "would be inverted by the body's displacement (its material forbids it)" : std::string();
}

void Model::tangent_mult(Vec d, Vec out) {
  ReadView x(u_linearization_);
  ReadView direction(d);
  WriteView result(out);
  // P d in a buffer kept between products (a new one per product cost page faults).
  projected_direction_.assign(direction.span().begin(), direction.span().end());
  constraints_.project(projected_direction_);
  EvaluationReport report;
  body_.tangent_apply(x.span(), projected_direction_, result.span(), report);
  constraints_.project(result.span());
  constraints_.add_complement(direction.span(), result.span(), constraint_stiffness());  // + c (I − P) d
  if (operator_scale_ != 1)
    for (double& x : result.span()) x *= operator_scale_;
  throw_if_domain_error(report);
}

PetscErrorCode Model::tangent_mult_callback(Mat A, Vec d, Vec out) {
  return petsc_callback("snede tangent shell MatMult", [&] {
    void* context = nullptr;
    SNEDE_PETSC(MatShellGetContext(A, &context));
    callback_owner<Model>(context, "Body").tangent_mult(d, out);
  });
}

PetscErrorCode Model::tangent_diagonal_callback(Mat A, Vec diagonal) {
  return petsc_callback("snede tangent shell MatGetDiagonal", [&] {
    void* context = nullptr;
    SNEDE_PETSC(MatShellGetContext(A, &context));
    const Model& model = callback_owner<Model>(context, "Body");
    tangent_diagonal(model, model.u_linearization_, diagonal);
  });
}

void Model::on_change(const Connectivity&, const ConnectivityChange& change) {
  loads_changed();  // gravity follows the element masses
  constraint_stiffness_ = 0;  // the cells' mean size
  if (change.vertex_events.empty()) return;
  const VertexId n_new = body_.mesh().n_points();
  constraints_.resize(n_new);
  for (const VertexEvent& event : change.vertex_events) {
    if (event.kind == VertexEventKind::added) constraints_.inherit(event.vertex, event.parents);
    if (event.kind == VertexEventKind::removed) constraints_.remove(event.vertex);
  }
  for (auto& entry : channels_) {  // loads are not inherited: a new or removed vertex carries none
    entry.second.resize(body_.n_dofs(), 0.0);
    for (const VertexEvent& event : change.vertex_events)
      if (event.kind != VertexEventKind::moved)
        std::fill_n(entry.second.begin() + static_cast<std::ptrdiff_t>(event.vertex) * dim(), dim(), 0.0);
  }
  std::vector<Vec*> fields{u_.slot()};
  fields.insert(fields.end(), carried_fields_.begin(), carried_fields_.end());
  if (n_new != n_points_) {
    // New Vecs over the old ones' storage while it has room (core/growable_vec.hpp): the
    // reissue costs the rows added, not a copy of every row. The linearization point keeps
    // its rows, as in a change of the same size: a solver sets it before it linearizes.
    for (Vec* field : fields) resize_growable_vec(field, n_dofs());
    resize_growable_vec(u_linearization_.slot(), n_dofs());
    n_points_ = n_new;
    create_tangent();
    ++generation_;
  }
  for (Vec* field : fields) replay_vertex_events(WriteView(*field).span(), dim(), change.vertex_events);  // O(events)
}

}  // namespace snede
