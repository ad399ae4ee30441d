#include "problem/model_problem.hpp"

#include <limits>
#include <vector>

#include "core/norms.hpp"
#include "core/petsc_util.hpp"
#include "fem/stable_time_step.hpp"
#include "problem/tangent_assembly.hpp"

namespace snede {
namespace {

class AssembledModelTangent final : public AssembledProblemTangent {
 public:
  AssembledModelTangent(Model& model, MatrixFormat format)
      : model_(model), edits_(model.body().mesh().connectivity()), tangent_(model, format, MembraneTangent::positive_part) {
    set_rigid_body_near_null_space(model, tangent_.mat());
  }
  // The tangent of the edited mesh from `earlier`'s, its values too given u (tangent_assembly.hpp).
  AssembledModelTangent(Model& model, const AssembledModelTangent& earlier, Vec u)
      : model_(model), edits_(model.body().mesh().connectivity()), tangent_(model, earlier.tangent_, earlier.edits_, u) {
    set_rigid_body_near_null_space(model, tangent_.mat());
  }
  Mat mat() const override { return tangent_.mat(); }
  void assemble(Vec u) override { tangent_.assemble(model_, u); }
  bool matches() const override { return tangent_.matches(model_); }
  bool follow_moved_vertices() override {
    if (!tangent_.follow_moved_vertices(model_)) return false;
    set_rigid_body_near_null_space(model_, tangent_.mat());  // the rigid motions of the moved vertices
    return true;
  }
  std::unique_ptr<AssembledProblemTangent> follow_edits(Vec u) override {
    if (!tangent_.can_follow_edits(model_)) return nullptr;
    const bool values = u && !model_.body().tangent_depends_on_state() && tangent_.values_can_follow_edits(model_);
    return std::make_unique<AssembledModelTangent>(model_, *this, values ? u : nullptr);
  }
  bool filled() const override { return tangent_.filled(); }

 private:
  Model& model_;
  EditFootprint edits_;  // since this tangent was made
  AssembledTangent tangent_;
};

}  // namespace

std::unique_ptr<AssembledProblemTangent> ModelProblem::make_assembled_tangent(MatrixFormat format) {
  return std::make_unique<AssembledModelTangent>(model_, format);
}

ResidualCheck ModelProblem::residual(Vec u, Vec F) {
  EvaluationReport report;
  model_.residual(u, F, report);
  return {report.domain_errors.empty(), !report.inverted.empty() && forbids_inversion(model_.body().material())};
}

std::string ModelProblem::inadmissible(Vec u) {
  std::string why;
  return model_.admissible(u, &why) ? std::string() : why;
}

double ModelProblem::energy(Vec u) {
  EvaluationReport report;
  const double energy = model_.potential_energy(u, report);
  return report.domain_errors.empty() ? energy : std::numeric_limits<double>::quiet_NaN();
}

double ModelProblem::external_force_norm() { return euclidean_norm(model_.external_forces()); }

void ModelProblem::project_onto_allowed_motions(Vec v) {
  WriteView values(v);
  model_.constraints().project(values.span());
}

bool ModelProblem::every_dof_prescribed() const {
  return model_.constraints().n_constrained_components() == static_cast<std::size_t>(model_.n_dofs());
}

void ModelProblem::inverse_lumped_mass(Vec out) {
  const std::vector<double> mass = model_.body().lumped_mass();
  const int dim = model_.dim();
  std::vector<double> inverse(mass.size() * dim);
  for (std::size_t v = 0; v < mass.size(); ++v)
    for (int k = 0; k < dim; ++k) inverse[v * dim + k] = mass[v] > 0 ? 1 / mass[v] : 0.0;
  set_vec_values(out, inverse);
}

double ModelProblem::cfl_time_step() {
  const ElasticBody& body = model_.body();
  return snede::cfl_time_step(body.mesh(), body.material(), body.density());
}

double ModelProblem::flops_per_residual() const {
  return static_cast<double>(model_.body().flops_per_element().force) *
         static_cast<double>(model_.body().mesh().n_cells());
}

}  // namespace snede
