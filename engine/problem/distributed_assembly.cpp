#include "problem/distributed_assembly.hpp"

#include "core/error.hpp"
#include "problem/projected_stiffness.hpp"

namespace snede {
namespace {

// P's blocks when whole dofs are fixed: diagonal, 0 on a fixed dof and 1 on a free one.
std::vector<double> diagonal_projection(std::span<const std::uint8_t> fixed_local, int dim) {
  std::vector<double> blocks(fixed_local.size() * static_cast<std::size_t>(dim));
  for (std::size_t dof = 0; dof < fixed_local.size(); ++dof)
    blocks[dof * dim + dof % dim] = fixed_local[dof] ? 0.0 : 1.0;
  return blocks;
}

}  // namespace

DistributedAssembledTangent::DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body,
                                                         std::span<const PetscInt> local_rows,
                                                         std::span<const std::uint8_t> fixed_local, PetscInt n_owned_dofs,
                                                         double constraint_stiffness)
    : DistributedAssembledTangent(part, body, local_rows, diagonal_projection(fixed_local, part.local->dim()),
                                  n_owned_dofs, constraint_stiffness) {}

DistributedAssembledTangent::DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body,
                                                         std::span<const PetscInt> local_rows,
                                                         std::span<const double> projection, PetscInt n_owned_dofs,
                                                         double constraint_stiffness)
    : part_(part), body_(body), local_rows_(local_rows.begin(), local_rows.end()),
      projection_(projection.begin(), projection.end()),
      complement_(complement_blocks(projection_, part.local->dim())) {
  for (double& x : complement_) x *= constraint_stiffness;
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
  const bool membrane = part_.local->is_surface();
  MembranePositivePart positive_part;
  std::vector<PetscInt> rows;
  for_each_projected_element_matrix(body_, u, projection_, [&](ElementId, std::span<const VertexId> vertices,
                                                               std::span<const double> element_matrix) {
    const std::span<const double> K = membrane ? positive_part(element_matrix) : element_matrix;
    const std::size_t n = vertices.size() * dim;
    rows.resize(n);
    for (std::size_t i = 0; i < n; ++i) rows[i] = local_rows_[static_cast<std::size_t>(vertices[i / dim]) * dim + i % dim];
    SNEDE_PETSC(MatSetValues(target, static_cast<PetscInt>(n), rows.data(), static_cast<PetscInt>(n), rows.data(), K.data(),
                             ADD_VALUES));
  });
  // + c (I − P) on every owned vertex's diagonal block (zero for a free one), so every owned row
  // has its diagonal entry and a constrained direction the stiffness c, as in the shell.
  for (std::size_t v = 0; v < part_.owned.size(); ++v)
    if (part_.owned[v])
      SNEDE_PETSC(MatSetValues(target, static_cast<PetscInt>(dim), &local_rows_[v * dim], static_cast<PetscInt>(dim),
                               &local_rows_[v * dim], &complement_[v * dim * dim], ADD_VALUES));
  SNEDE_PETSC(MatAssemblyBegin(target, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(target, MAT_FINAL_ASSEMBLY));
}

void DistributedAssembledTangent::assemble(std::span<const double> u) {
  SNEDE_PETSC(MatZeroEntries(A_));
  add_elements(A_, u);
}

}  // namespace snede
