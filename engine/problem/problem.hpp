// What a solver needs of a static problem, whatever communicator it lives on (issue 36): the
// state, the residual F(u) = P∇Π(u) + c (I − P)(u − ū) and the energy (c: a stiffness of the
// problem's own units for the constrained directions, so that nothing depends on E or the
// length unit, issue 48), the lumped masses, the constraints' projection, and the scales of
// the stopping rule (6.9). The serial Model is the
// one-rank problem (ModelProblem); DistributedStatic is the problem over a distributed mesh.
// A solver written against Problem runs unchanged on 1 or N ranks, as PETSc's tutorials run
// the same code on any number of processes. Every member is collective on comm().
#pragma once

#include <petscmat.h>
#include <petscvec.h>

#include <cstdint>
#include <memory>
#include <string>

#include "core/exclusive_use.hpp"
#include "fem/material.hpp"

namespace snede {

// What an evaluation of F found wrong with the state.
struct ResidualCheck {
  bool finite = true;     // every element's forces were finite
  bool inverted = false;  // an element is inverted and the material forbids it
  bool admissible() const { return finite && !inverted; }
};

// An assembled copy of a problem's tangent, for the preconditioners that need entries (GAMG,
// ILU, LU, Galerkin multigrid levels): the same J = P K P + c (I − P) as the shell, times the
// operator scale, with the rigid-body motions as near null space.
class AssembledProblemTangent {
 public:
  virtual ~AssembledProblemTangent() = default;
  virtual Mat mat() const = 0;
  // Fills the entries at the state u (collective).
  virtual void assemble(Vec u) = 0;
  // Whether the sparsity is still the problem's (no edit of the mesh since it was made).
  virtual bool matches() const = 0;
  // Takes over a mesh whose vertices only moved since (a cut's snap): true, the sparsity kept
  // and the next assemble() filling the values for the new shapes; false if elements or vertices
  // were added or removed (a new tangent is needed).
  virtual bool follow_moved_vertices() { return false; }
  // The tangent of the mesh as edited since this one was made (a cut, a refinement), made from
  // this one: its sparsity, and, given u and where that is J exactly (a tangent that does not
  // depend on the state), its values: this one's where no edit reached, J at u in the blocks of
  // the vertices the edits touched (tangent_assembly.hpp); else zero values, for assemble().
  // Null where it cannot be made so (then a new tangent is made and assembled).
  virtual std::unique_ptr<AssembledProblemTangent> follow_edits(Vec /*u*/) { return nullptr; }
  // Whether the values are J's at some state (a tangent follow_edits made with its values).
  virtual bool filled() const { return false; }
};

// How an assembled tangent stores its entries: AIJ for PETSc's preconditioners, vertex blocks
// (BAIJ) where multigrid levels read them by blocks.
enum class MatrixFormat { aij, baij };

class Problem {
 public:
  virtual ~Problem() = default;

  virtual MPI_Comm comm() const = 0;
  virtual int dim() const = 0;
  virtual const Material& material() const = 0;
  // The displacement, solved in place (block size dim; the rows this rank owns).
  virtual Vec state() const = 0;

  // F(u) (6.7): the net force on the allowed motions, u − ū on the prescribed ones.
  virtual ResidualCheck residual(Vec u, Vec F) = 0;
  // ‖reactions‖ from the latest residual().
  virtual double last_reaction_norm() const = 0;
  // Why `u` cannot be a result ("DIVERGED_INVERTED_ELEMENTS", …), or empty.
  virtual std::string inadmissible(Vec u) = 0;
  // Π(u) = Π_int(u) − f_extᵀu: +∞ for an inverted element of a material that forbids it, NaN
  // when an element's energy is not finite (the kernels skip such an element).
  virtual double energy(Vec u) = 0;

  // The scales of (6.9): ‖f_ext‖, the force scale E·H² (E·t·H in 2D), and the dofs.
  virtual double external_force_norm() = 0;
  virtual double force_scale() = 0;
  virtual std::int64_t n_global_dofs() const = 0;

  // The tangent J = P K P + c (I − P) at the linearisation point, applied matrix-free (a MatShell
  // on comm() with MatMult and MatGetDiagonal), times the operator scale.
  virtual Mat tangent() const = 0;
  virtual void set_linearization_point(Vec u) = 0;
  // A solver divides a whole system by a force scale to keep CG's dot products in range: the
  // shell and the assembled tangent then apply scale·J; 1 otherwise.
  virtual void set_operator_scale(double scale) = 0;
  // A new assembled tangent in `format` for the current mesh (sparsity found now).
  virtual std::unique_ptr<AssembledProblemTangent> make_assembled_tangent(MatrixFormat format) = 0;
  // Cells over all ranks.
  virtual std::int64_t n_global_cells() const = 0;
  // Changes whenever the constraints' projection changes (a vertex fixed, released or made to
  // slide): what a preconditioner filled for earlier constraints compares.
  virtual std::uint64_t projection_fingerprint() const = 0;

  // Puts u on the constraints (prescribed values, sliding lines).
  virtual void enforce_constraints(Vec u) = 0;
  // v onto the motions the constraints allow.
  virtual void project_onto_allowed_motions(Vec v) = 0;
  virtual bool every_dof_prescribed() const = 0;

  // 1/m per dof from the lumped masses (§2.5), 0 for a vertex without mass.
  virtual void inverse_lumped_mass(Vec out) = 0;
  // (2.61) on the whole mesh.
  virtual double cfl_time_step() = 0;
  // Floating-point operations of one residual's element loop (a step's cost, §4.4.1).
  virtual double flops_per_residual() const = 0;

  // A mesh that changes (cuts, refinement) reissues the unknowns: the count changes with
  // every reissue, and the fields registered here are carried over like the state. A
  // problem whose mesh does not change keeps 0 and carries nothing.
  virtual std::uint64_t generation() const { return 0; }
  virtual void add_carried_field(Vec* /*field*/) {}
  virtual void remove_carried_field(Vec* /*field*/) {}

  // The state's owner, claimed by each solve for its duration (one thread at a time).
  virtual ExclusiveUse& exclusive_use() = 0;
};

}  // namespace snede
