// The tangent of a distributed static problem assembled into a PETSc MPIAIJ matrix, for the
// preconditioners that need entries (GAMG, issue 18). Each rank adds the element stiffnesses
// of its own cells, projected on both sides by the constraints (P_a K_ab P_b, the kernels of
// ElasticBody as the serial AssembledTangent takes them: projected_stiffness.hpp) at the global
// rows of their vertices; PETSc sends the ghosts' shares to their owners at assembly. The
// owners add each of their vertices' block of c (I − P): J = P K P + c (I − P), as the shell
// applies it (c the constrained directions' stiffness, projected_stiffness.hpp).
// A membrane element contributes its positive part, as serially for a preconditioner. The
// sparsity is found once (MATPREALLOCATOR), and the rigid-body motions of the reference
// configuration are the near null space GAMG coarsens with.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/petsc_handle.hpp"
#include "fem/elastic_body.hpp"
#include "mesh/distributed_mesh.hpp"

namespace snede {

class DistributedAssembledTangent {
 public:
  // Collective. local_rows: the global row of each local dof (owned and ghost); projection: P's
  // dim × dim block (row-major) of each local vertex, one after another (projection_blocks);
  // n_owned_dofs: the rows this rank owns; constraint_stiffness: c (the same on every rank).
  DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body, std::span<const PetscInt> local_rows,
                              std::span<const double> projection, PetscInt n_owned_dofs,
                              double constraint_stiffness = 1.0);
  // The same with whole dofs fixed: fixed_local is 1 for a fixed local dof (P's blocks are
  // diagonal, 0 there and 1 elsewhere).
  DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body, std::span<const PetscInt> local_rows,
                              std::span<const std::uint8_t> fixed_local, PetscInt n_owned_dofs,
                              double constraint_stiffness = 1.0);
  // Collective: J at the local displacement u (owned and ghost dofs).
  void assemble(std::span<const double> u);
  Mat mat() const { return A_; }

 private:
  // Adds every cell's projected stiffness to `target` and c (I − P) on this rank's owned vertices.
  void add_elements(Mat target, std::span<const double> u);

  const DistributedMesh& part_;
  const ElasticBody& body_;
  std::vector<PetscInt> local_rows_;
  std::vector<double> projection_, complement_;  // per local vertex, dim × dim blocks: P, c (I − P)
  MatHandle A_;
};

}  // namespace snede
