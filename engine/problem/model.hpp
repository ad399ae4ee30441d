// The model (§2.4, §3.1, §6.6): an elastic body with constraints, loads and a displacement
// state held in PETSc vectors. The potential is a sum of named terms: the elastic body's
// Π_int, gravity, and named nodal-force channels ("nodal", the needle's "friction", ...),
// each set, changed or cleared alone.
//
// It is a connectivity watcher: it replays a change's vertex events on the state and on every
// carried field (a dynamic solver's velocity) — an added vertex gets the weighted sum of its
// parents' values, a vertex moved by parents is re-interpolated, a removed vertex is taken
// out of the problem (held at zero) — and reissues vector and shell sizes when the vertex
// count changed, in time proportional to the vertices added (the vectors keep spare room).
//
// The static problem is min Π(u) = Π_int(u) − f_extᵀu under the constraints. PETSc sees
//   F(u) = P ∇Π(u) + c (I − P)(u − anchor)    (residual; zero exactly at the solution)
//   J    = P K(u) P + c (I − P)                (tangent shell, applied matrix-free)
// so that search directions and tangents are projected onto the allowed motions (6.7); c, the
// constrained directions' stiffness, is about a diagonal entry of K (constraint_stiffness()).
#pragma once

#include <petscmat.h>
#include <petscvec.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/exclusive_use.hpp"
#include "core/petsc_handle.hpp"
#include "fem/elastic_body.hpp"
#include "problem/constraints.hpp"

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
  // Claimed by every solve, cut and needle step on this body (one thread at a time).
  ExclusiveUse& exclusive_use() { return exclusive_use_; }

  Constraints& constraints() { return constraints_; }
  const Constraints& constraints() const { return constraints_; }
  void fix(std::span<const VertexId> vertices, std::span<const double> values);
  void slide(std::span<const VertexId> vertices, std::span<const double> direction);

  // Gravity (dim components) on the lumped element masses; replaces a previous gravity.
  void set_gravity(std::span<const double> g);
  void clear_gravity();
  bool has_gravity() const { return !gravity_.empty(); }
  // Nodal forces in the load channel `channel` (created on first use): one dim-vector for all
  // listed vertices or one per vertex. add_ accumulates, set_ replaces the whole channel.
  void add_nodal_force(const std::string& channel, std::span<const VertexId> vertices, std::span<const double> forces);
  void set_nodal_forces(const std::string& channel, std::span<const VertexId> vertices, std::span<const double> forces);
  void clear_channel(const std::string& channel);
  // Clears gravity and every channel.
  void clear_loads();
  std::vector<std::string> load_channels() const;
  // One channel's forces, (n_points, dim) flattened (zeros for an unknown channel).
  std::vector<double> channel_forces(const std::string& channel) const;
  // f_ext = gravity + all channels, (n_points, dim) flattened.
  const std::vector<double>& external_forces();

  // A nodal field (block size dim, n_dofs entries) that follows the mesh like the state:
  // replayed vertex events, reissued (the Vec is replaced) when the size changes.
  void add_carried_field(Vec* field);
  void remove_carried_field(Vec* field);

  Vec displacement() const { return u_; }  // the state; owned by the model
  Mat tangent() const { return tangent_; }  // J at the linearisation point (times operator_scale)
  // The shell applies scale·J: a solver may divide a whole linear system by a force scale
  // to keep CG's dot products in range; 1 otherwise.
  void set_operator_scale(double scale) { operator_scale_ = scale; }
  double operator_scale() const { return operator_scale_; }
  Vec linearization_point() const { return u_linearization_; }
  void set_linearization_point(Vec u);

  // Π(u) = Π_int(u) − f_extᵀu (+∞ for an inverted element of a material forbidding it).
  double potential_energy(Vec u, EvaluationReport& report);
  // F(u) above. Also records ‖f_react‖ = ‖(I − P)∇Π(u)‖ for the stopping criterion (6.9).
  void residual(Vec u, Vec F, EvaluationReport& report);
  // Reaction forces (I − P)∇Π(u): what the supports exert on the body.
  void reaction_forces(Vec u, Vec R);
  // ∇Π(u) = −f_int(u) − f_ext, unprojected, (n_points, dim) flattened: at a constrained vertex
  // in equilibrium, the force its support exerts on the body. The one residual() computed last
  // when u, the loads and the mesh are as they were then (a solver's final residual serves the
  // needle's rearrangement, §6.3.2, without another pass over the elements).
  std::vector<double> potential_gradient(Vec u);
  // u ← P u + (I − P) anchor.
  void enforce_constraints(Vec u) const;
  double last_reaction_norm() const { return last_reaction_norm_; }
  // E·H² in 3D, E·t·H in 2D (H = diameter of the reference body): the force scale of (6.9).
  double force_scale() const;
  // c of F and J above, in N/m (projected_stiffness.hpp: (λ + 2μ)·ℓ in 3D, ℓ the mean cell's
  // size; E/(1 − ν²)·t for sheets and membranes), so that the constrained block is of the
  // stiffness's size whatever the units. Computed once per mesh (after each change).
  double constraint_stiffness() const;
  // True if u is finite and, under a material that forbids inversion, has no element with
  // det F ≤ det_floor (0: none inverted or flat).
  bool admissible(Vec u, std::string* why = nullptr, double det_floor = 0.0) const;

  void init(const Connectivity&) override {}
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;
  // A planned cell the displacement would invert (a material that forbids it, as admissible()
  // judges: det F ≤ 0, or a membrane triangle collapsed to a line), exactly, in X + u.
  std::string refuses(const Simplex& cell) const override;

 private:
  void create_vectors();
  void create_tangent();
  void tangent_mult(Vec d, Vec out);
  static PetscErrorCode tangent_mult_callback(Mat A, Vec d, Vec out);
  // The shell's MatGetDiagonal (for PCJACOBI): the diagonal of J without forming J.
  static PetscErrorCode tangent_diagonal_callback(Mat A, Vec diagonal);

  std::vector<double>& channel(const std::string& name);
  void loads_changed();  // f_ext and the remembered ∇Π are stale

  // A state as PETSc tells it apart: the Vec and its write count.
  struct GradientKey {
    PetscObjectId vec = 0;
    PetscObjectState state = 0;
    bool operator==(const GradientKey&) const = default;
  };
  static GradientKey key_of(Vec u);
  struct RememberedGradient {
    std::vector<double> values;  // ∇Π at the state of key
    GradientKey key;
    bool valid = false;
  };

  ElasticBody& body_;
  Constraints constraints_;
  std::vector<double> gravity_;        // dim components, or empty
  std::map<std::string, std::vector<double>> channels_;  // name → n_dofs nodal forces
  std::vector<Vec*> carried_fields_;
  std::vector<double> projected_direction_;  // tangent_mult's P d
  std::vector<double> external_;       // cached f_ext
  bool external_valid_ = false;
  RememberedGradient gradient_;  // from the last residual()
  VertexId n_points_ = 0;
  VecHandle u_;
  VecHandle u_linearization_;
  MatHandle tangent_;
  std::uint64_t generation_ = 0;
  ExclusiveUse exclusive_use_;
  double last_reaction_norm_ = 0;
  double operator_scale_ = 1;
  mutable double constraint_stiffness_ = 0;  // 0 until computed for the current mesh
};

}  // namespace snede
