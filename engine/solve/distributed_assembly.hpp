// The tangent of a distributed static problem assembled into a PETSc MPIAIJ matrix, for the
// preconditioners that need entries (GAMG, issue 18). Each rank adds the element stiffnesses
// of its own cells (the kernels of ElasticBody, fixed rows and columns removed) at the global
// rows of their vertices; PETSc sends the ghosts' shares to their owners at assembly. The
// owners add the identity on fixed rows: J = P K P + I − P, as the shell applies it. The
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
  // Collective. local_rows: the global row of each local dof (owned and ghost); fixed_local:
  // 1 for a fixed local dof; n_owned_dofs: the rows this rank owns.
  DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body, std::span<const PetscInt> local_rows,
                              std::span<const std::uint8_t> fixed_local, PetscInt n_owned_dofs);
  // Collective: J at the local displacement u (owned and ghost dofs).
  void assemble(std::span<const double> u);
  Mat mat() const { return A_; }

 private:
  // Adds every cell's (masked) stiffness to `target` and 1 on this rank's owned fixed rows.
  void add_elements(Mat target, std::span<const double> u);

  const DistributedMesh& part_;
  const ElasticBody& body_;
  std::vector<PetscInt> local_rows_;
  std::vector<std::uint8_t> fixed_local_;
  MatHandle A_;
};

}  // namespace snede
