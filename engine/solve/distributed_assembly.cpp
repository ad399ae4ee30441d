#include "solve/distributed_assembly.hpp"

#include "core/error.hpp"

namespace snede {

DistributedAssembledTangent::DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body,
                                                         std::span<const PetscInt> local_rows,
                                                         std::span<const std::uint8_t> fixed_local, PetscInt n_owned_dofs)
    : part_(part), body_(body), local_rows_(local_rows.begin(), local_rows.end()),
      fixed_local_(fixed_local.begin(), fixed_local.end()) {
  const int dim = part.local->dim();
  const std::vector<double> at_rest(local_rows_.size(), 0.0);
  MatHandle sparsity;
  SNEDE_PETSC(MatCreate(part.comm, sparsity.out()));
  SNEDE_PETSC(MatSetType(sparsity, MATPREALLOCATOR));
  SNEDE_PETSC(MatSetSizes(sparsity, n_owned_dofs, n_owned_dofs, PETSC_DETERMINE, PETSC_DETERMINE));
  SNEDE_PETSC(MatSetBlockSize(sparsity, dim));
  SNEDE_PETSC(MatSetUp(sparsity));
  add_elements(sparsity, at_rest);
  SNEDE_PETSC(MatCreate(part.comm, A_.out()));
  SNEDE_PETSC(MatSetType(A_, MATAIJ));
  SNEDE_PETSC(MatSetSizes(A_, n_owned_dofs, n_owned_dofs, PETSC_DETERMINE, PETSC_DETERMINE));
  SNEDE_PETSC(MatSetBlockSize(A_, dim));
  SNEDE_PETSC(MatPreallocatorPreallocate(sparsity, PETSC_TRUE, A_));
  SNEDE_PETSC(MatSetOption(A_, MAT_SYMMETRIC, PETSC_TRUE));

  // The rigid-body motions from the owned vertices' reference coordinates.
  VecHandle coordinates;
  SNEDE_PETSC(VecCreateMPI(part.comm, n_owned_dofs, PETSC_DETERMINE, coordinates.out()));
  SNEDE_PETSC(VecSetBlockSize(coordinates, dim));
  const std::vector<double>& points = part.local->points();
  for (std::size_t v = 0; v < part.owned.size(); ++v)
    if (part.owned[v])
      SNEDE_PETSC(VecSetValues(coordinates, dim, &local_rows_[v * dim], &points[v * dim], INSERT_VALUES));
  SNEDE_PETSC(VecAssemblyBegin(coordinates));
  SNEDE_PETSC(VecAssemblyEnd(coordinates));
  MatNullSpace rigid = nullptr;
  SNEDE_PETSC(MatNullSpaceCreateRigidBody(coordinates, &rigid));
  const PetscErrorCode set = MatSetNearNullSpace(A_, rigid);
  MatNullSpaceDestroy(&rigid);
  SNEDE_PETSC(set);
}

void DistributedAssembledTangent::add_elements(Mat target, std::span<const double> u) {
  const auto dim = static_cast<std::size_t>(part_.local->dim());
  std::vector<PetscInt> rows;
  std::vector<double> masked;
  body_.for_each_element_stiffness(u, [&](ElementId, std::span<const VertexId> vertices, std::span<const double> K) {
    const std::size_t n = vertices.size() * dim;
    rows.resize(n);
    masked.assign(K.begin(), K.end());
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t dof = static_cast<std::size_t>(vertices[i / dim]) * dim + i % dim;
      rows[i] = local_rows_[dof];
      if (!fixed_local_[dof]) continue;
      for (std::size_t j = 0; j < n; ++j) masked[i * n + j] = masked[j * n + i] = 0.0;
    }
    SNEDE_PETSC(MatSetValues(target, static_cast<PetscInt>(n), rows.data(), static_cast<PetscInt>(n), rows.data(),
                             masked.data(), ADD_VALUES));
  });
  // Every owned row gets its diagonal entry (1 on a fixed row, 0 added elsewhere).
  for (std::size_t dof = 0; dof < local_rows_.size(); ++dof)
    if (part_.owned[dof / dim])
      SNEDE_PETSC(MatSetValue(target, local_rows_[dof], local_rows_[dof], fixed_local_[dof] ? 1.0 : 0.0, ADD_VALUES));
  SNEDE_PETSC(MatAssemblyBegin(target, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(target, MAT_FINAL_ASSEMBLY));
}

void DistributedAssembledTangent::assemble(std::span<const double> u) {
  SNEDE_PETSC(MatZeroEntries(A_));
  add_elements(A_, u);
}

}  // namespace snede
