// The model (§2.4, §3.1, §6.6): an elastic body with constraints, loads and a displacement
// state held in PETSc vectors. It is a connectivity watcher: after a mesh change it reissues
// vector and shell sizes and carries the displacement over (surviving vertices keep theirs;
// a new vertex gets the weighted sum of its parents' — the value of the element it was
// created in: a copy keeps its original's, an edge midpoint the mean of the endpoints').
//
// The static problem is min Π(u) = Π_int(u) − f_extᵀu under the constraints. PETSc sees
//   F(u) = P ∇Π(u) + (I − P)(u − anchor)      (residual; zero exactly at the solution)
//   J    = P K(u) P + (I − P)                  (tangent shell, applied matrix-free)
// so that search directions and tangents are projected onto the allowed motions (6.7).
#pragma once

#include <petscmat.h>
#include <petscvec.h>

#include <cstdint>
#include <vector>

#include "fem/elastic_body.hpp"
#include "solve/constraints.hpp"

namespace snede {

class Model : public ConnectivityWatcher {
 public:
  explicit Model(ElasticBody& body);
  ~Model() override;
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  ElasticBody& body() { return body_; }
  const ElasticBody& body() const { return body_; }
  int dim() const { return body_.dim(); }
  PetscInt n_dofs() const { return static_cast<PetscInt>(body_.n_dofs()); }
  // Increases whenever vector sizes change; solvers compare it to rebuild their objects.
  std::uint64_t generation() const { return generation_; }

  Constraints& constraints() { return constraints_; }
  const Constraints& constraints() const { return constraints_; }
  void fix(std::span<const VertexId> vertices, std::span<const double> values);
  void slide(std::span<const VertexId> vertices, std::span<const double> direction);

  void set_gravity(std::span<const double> g);
  void add_nodal_force(std::span<const VertexId> vertices, std::span<const double> forces);
  void clear_loads();
  // f_ext = gravity + nodal forces, (n_points, dim) flattened.
  const std::vector<double>& external_forces();

  Vec displacement() const { return u_; }  // the state; owned by the model
  Mat tangent() const { return tangent_; }  // J at the linearisation point
  void set_linearization_point(Vec u);

  // Π(u) = Π_int(u) − f_extᵀu (+∞ for an inverted element of a material forbidding it).
  double potential_energy(Vec u, EvaluationReport& report);
  // F(u) above. Also records ‖f_react‖ = ‖(I − P)∇Π(u)‖ for the stopping criterion (6.9).
  void residual(Vec u, Vec F, EvaluationReport& report);
  // Reaction forces (I − P)∇Π(u): what the supports exert on the body.
  void reaction_forces(Vec u, Vec R);
  // u ← P u + (I − P) anchor.
  void enforce_constraints(Vec u) const;
  double last_reaction_norm() const { return last_reaction_norm_; }
  // E·H² in 3D, E·t·H in 2D (H = diameter of the reference body): the force scale of (6.9).
  double force_scale() const;
  // True if u is finite and has no inverted element under a material that forbids it.
  bool admissible(Vec u, std::string* why = nullptr) const;

  // Carry a nodal field (n_points_old × dim) over to the current points by parents.
  std::vector<double> carried_over(std::span<const double> old_values, VertexId n_old_points) const;

  void init(const Connectivity&) override {}
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;

 private:
  void create_vectors();
  void tangent_mult(Vec d, Vec out);
  static PetscErrorCode tangent_mult_callback(Mat A, Vec d, Vec out);

  ElasticBody& body_;
  Constraints constraints_;
  std::vector<double> gravity_;        // dim components, or empty
  std::vector<double> nodal_forces_;   // n_dofs
  std::vector<double> external_;       // cached f_ext
  bool external_valid_ = false;
  VertexId n_points_ = 0;
  Vec u_ = nullptr;
  Vec u_linearization_ = nullptr;
  Mat tangent_ = nullptr;
  std::uint64_t generation_ = 0;
  double last_reaction_norm_ = 0;
};

}  // namespace snede
