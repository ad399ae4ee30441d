// The serial Model as the one-rank Problem (problem.hpp): what a solver written for any
// communicator reads of a body whose mesh is edited (cuts, bisection) in place.
#pragma once

#include "problem/model.hpp"
#include "problem/problem.hpp"

namespace snede {

class ModelProblem final : public Problem {
 public:
  explicit ModelProblem(Model& model) : model_(model) {}

  MPI_Comm comm() const override { return PETSC_COMM_SELF; }
  int dim() const override { return model_.dim(); }
  const Material& material() const override { return model_.body().material(); }
  Vec state() const override { return model_.displacement(); }
  ResidualCheck residual(Vec u, Vec F) override;
  double last_reaction_norm() const override { return model_.last_reaction_norm(); }
  std::string inadmissible(Vec u) override;
  double energy(Vec u) override;
  double external_force_norm() override;
  double force_scale() override { return model_.force_scale(); }
  std::int64_t n_global_dofs() const override { return model_.n_dofs(); }
  Mat tangent() const override { return model_.tangent(); }
  void set_linearization_point(Vec u) override { model_.set_linearization_point(u); }
  void set_operator_scale(double scale) override { model_.set_operator_scale(scale); }
  // AIJ or BAIJ over the mesh's vertex blocks; a membrane's elements give their positive part
  // (a compressed, wrinkling element is indefinite and must not make the preconditioner so).
  std::unique_ptr<AssembledProblemTangent> make_assembled_tangent(MatrixFormat format) override;
  std::int64_t n_global_cells() const override { return static_cast<std::int64_t>(model_.body().mesh().n_cells()); }
  std::uint64_t projection_fingerprint() const override { return model_.constraints().projection_fingerprint(); }
  void enforce_constraints(Vec u) override { model_.enforce_constraints(u); }
  void project_onto_allowed_motions(Vec v) override;
  bool every_dof_prescribed() const override;
  void inverse_lumped_mass(Vec out) override;
  double cfl_time_step() override;
  double flops_per_residual() const override;
  std::uint64_t generation() const override { return model_.generation(); }
  void add_carried_field(Vec* field) override { model_.add_carried_field(field); }
  void remove_carried_field(Vec* field) override { model_.remove_carried_field(field); }
  ExclusiveUse& exclusive_use() override { return model_.exclusive_use(); }

  Model& model() { return model_; }

 private:
  Model& model_;
};

}  // namespace snede
