// A static solve on a distributed mesh (issue 18): the body's unknowns are a PETSc vector on
// the mesh's communicator, a row block per owned vertex (PETSc's vertex numbering), and every
// rank evaluates the same element kernels (ElasticBody) on its own cells. Each evaluation
// scatters the state to the rank's vertices (owned and ghosts), evaluates locally, and adds
// the ghosts' contributions into their owners (a VecScatter, forward then reverse with
// ADD_VALUES); energies are summed over the ranks. The tangent is a matrix-free MatShell on the
// communicator, so PETSc's SNES and KSP run unchanged on any number of ranks; GAMG and the
// other preconditioners that need entries get an assembled MPIAIJ copy
// (distributed_assembly.hpp). It is a Problem (problem.hpp): the one StaticSolver and the one
// DynamicRelaxation drive it on any number of ranks, as they drive the serial Model.
//
// Constraints and loads are given by the serial mesh's vertex ids, the same on every rank:
// fixed vertices (all components) and their displacements, sliding vertices (each along a line
// through a given displacement), nodal forces, and gravity. Each rank holds the constraints of
// its vertices as the serial Model does (constraints.hpp, §3.1, §6.6): P the projection onto
// the allowed motions, the residual P(−f_int − f_ext) + c (I − P)(u − ū), the tangent
// P K P + c (I − P), c the constrained directions' stiffness (projected_stiffness.hpp), from
// the whole body's cells.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/petsc_handle.hpp"
#include "fem/elastic_body.hpp"
#include "mesh/distributed_mesh.hpp"
#include "problem/constraints.hpp"
#include "problem/distributed_assembly.hpp"
#include "problem/problem.hpp"
#include "problem/rank_piece_holding.hpp"

namespace snede {

struct DistributedConditions {
  std::vector<std::int64_t> fixed;     // serial vertex ids
  std::vector<double> fixed_values;    // dim per fixed vertex
  std::vector<std::int64_t> sliding;   // serial vertex ids, none of them fixed
  std::vector<double> sliding_directions;  // dim per sliding vertex: its line's direction (normalised here)
  std::vector<double> sliding_anchors;     // dim per sliding vertex: a displacement on its line (Body.slide: where it was)
  std::vector<std::int64_t> loaded;    // serial vertex ids
  std::vector<double> forces;          // dim per loaded vertex
  std::vector<double> gravity;         // dim components (m/s²), or empty for none
};

class DistributedStatic final : public Problem {
 public:
  // Collective. Throws std::invalid_argument (the same on every rank) for conditions of the
  // wrong size, ids outside the serial mesh, a vertex fixed at two displacements, sliding twice
  // or both fixed and sliding, a zero or non-finite direction or displacement, or arguments that
  // differ between the ranks (naming them, core/rank_agreement.hpp). The density sets gravity's load (ρ|τ|g shared
  // by each cell's corners, as serially) and the lumped masses of dynamic relaxation.
  DistributedStatic(DistributedMesh& part, Material material, double density, double thickness,
                    const DistributedConditions& conditions);
  ~DistributedStatic() override;
  DistributedStatic(const DistributedStatic&) = delete;
  DistributedStatic& operator=(const DistributedStatic&) = delete;

  // Collective: the state from a displacement in the serial mesh's vertex order
  // (n_global_vertices × dim, the same on every rank), a solve's starting point, made to meet
  // the constraints (Constraints::enforce: fixed vertices at their prescribed displacements,
  // sliding ones moved onto their lines). Empty: zero.
  void set_displacement(std::span<const double> serial_displacement);
  // Collective: the same from this rank's vertices' displacement, (n_local_vertices × dim) in the
  // part's local order; the owned vertices' values are taken (a ghost's comes from its owner), so
  // no rank holds a whole-body array. Throws on every rank when some rank's array has the wrong
  // size or a non-finite value.
  void set_local_displacement(std::span<const double> local_displacement);
  // Π(u) = Π_int(u) − f_extᵀu over the whole body (collective), at the state or at u.
  double energy() { return energy(u_); }
  double energy(Vec u) override;
  // The displacement of this rank's vertices (owned and ghosts), (n_local_vertices, dim).
  std::vector<double> local_displacement();
  // This rank's cells (local element ids) that `local_displacement` ((n_local_vertices, dim))
  // inverts, as ElasticBody::inverted_elements finds them. Local: no communication.
  std::vector<ElementId> inverted_local_elements(std::span<const double> local_displacement) const {
    return body_.inverted_elements(local_displacement);
  }

  // Collective: throws the same std::invalid_argument on every rank when a piece of the body,
  // wherever its cells lie, is not held by the constraints (rank_piece_holding.hpp).
  void require_held() const;
  // Collective: the body's pieces and those the constraints leave loose (rank_piece_holding.hpp).
  RankPieces pieces() const;

  // What the solvers (SNES callbacks, DynamicRelaxation) use. All collective.
  // F = P(−f_int(u) − f_ext) + c (I − P)(u − ū). Not admissible when an element on some rank is
  // inverted (for a material that forbids it) or not finite; F is then NaN on every rank.
  ResidualCheck residual(Vec u, Vec F) override;
  // ‖reactions‖ ((I − P)(−f_int − f_ext), the constrained directions') from the latest residual().
  double last_reaction_norm() const override { return last_reaction_norm_; }
  std::string inadmissible(Vec u) override;
  // Why the latest residual() failed ("DIVERGED_INVERTED_ELEMENTS", "DIVERGED_NONFINITE_STATE"),
  // or empty.
  const std::string& last_failure() const { return last_failure_; }
  double external_force_norm() override;
  // (6.9)'s force scale E·H² (E·t·H in 2D), H the whole body's diameter.
  double force_scale() override;
  // c of F and J (the serial Model's constraint_stiffness, the same on every rank).
  double constraint_stiffness() const { return constraint_stiffness_; }
  // 1/m per owned dof from the lumped masses (§2.5) summed over the ranks, 0 without mass.
  void inverse_lumped_mass(Vec out) override;
  // (2.61) on the whole mesh: the smallest over the ranks.
  double cfl_time_step() override;
  double flops_per_residual() const override;
  // v ← P v (a motion the constraints allow).
  void project_onto_allowed_motions(Vec v) override;
  // u ← P u + (I − P) ū: the nearest displacement that meets the constraints.
  void enforce_constraints(Vec u) override;
  bool every_dof_prescribed() const override;
  Mat tangent() const override { return tangent_; }
  void set_linearization_point(Vec u) override { to_local(u, u_linearization_); }
  void set_operator_scale(double scale) override { operator_scale_ = scale; }
  // An MPIAIJ copy of the tangent (distributed_assembly.hpp; vertex blocks of size dim, either
  // format), for GAMG, block Jacobi, SOR, MUMPS's LU and Galerkin multigrid levels.
  std::unique_ptr<AssembledProblemTangent> make_assembled_tangent(MatrixFormat format) override;
  std::int64_t n_global_cells() const override { return part_.n_global_cells; }
  // The constraints are fixed when the problem is made.
  std::uint64_t projection_fingerprint() const override { return 0; }
  // The parts of the rank's mesh: its cells, vertices, which it owns and their rows; the
  // constraints of its local vertices, owned and ghost (for multigrid levels made on each
  // rank's vertices).
  const DistributedMesh& part() const { return part_; }
  const Constraints& local_constraints() const { return constraints_; }
  void tangent_mult(Vec d, Vec out);
  void tangent_diagonal(Vec diagonal);

  Vec state() const override { return u_; }
  MPI_Comm comm() const override { return part_.comm; }
  int dim() const override { return dim_; }
  const Material& material() const override { return body_.material(); }
  std::int64_t n_global_dofs() const override { return part_.n_global_vertices * dim_; }
  ExclusiveUse& exclusive_use() override { return exclusive_use_; }

 private:
  ExclusiveUse exclusive_use_;
  friend class AssembledDistributedTangent;
  void to_local(Vec global, std::vector<double>& local);
  // Writes value(local dof) into each owned row of the state, then meets the constraints.
  template <class ValueOfLocalDof>
  void assign_owned(ValueOfLocalDof value);
  void add_to_global(const std::vector<double>& local, Vec global);

  DistributedMesh& part_;
  bool inputs_agreed_;  // checked across the ranks before anything below can throw on one alone
  ElasticBody body_;
  int dim_;
  Constraints constraints_;        // per local vertex (owned and ghost), for the element kernels
  Constraints owned_constraints_;  // per owned vertex in row order, for the rank's entries of a Vec
  std::vector<double> projection_, complement_;  // P's and c (I − P)'s block of each local vertex
  double constraint_stiffness_ = 1;              // c
  std::vector<double> load_owned_;          // per owned dof (forces counted once, at the owner)
  std::vector<PetscInt> local_rows_;        // global row of each local dof (owned and ghost)
  std::vector<PetscInt> owned_rows_;        // global row of each owned dof, in local order
  std::vector<PetscInt> owned_local_dof_;   // local dof of each owned dof
  VecHandle u_, work_;
  Vec local_vec_ = nullptr;                 // sequential, all local dofs
  VecScatter scatter_ = nullptr;
  MatHandle tangent_;
  double operator_scale_ = 1;
  double last_reaction_norm_ = 0;
  std::string last_failure_;
  std::vector<double> u_local_, u_linearization_, d_local_, out_local_;
};

}  // namespace snede
