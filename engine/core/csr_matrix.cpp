#include "core/csr_matrix.hpp"

#include "core/error.hpp"

namespace snede {

MatHandle matrix_owning(std::unique_ptr<CsrArrays> arrays, PetscInt rows, PetscInt columns) {
  MatHandle A;
  SNEDE_PETSC(MatCreateSeqAIJWithArrays(PETSC_COMM_SELF, rows, columns, arrays->row_start.data(),
                                        arrays->columns.data(), arrays->values.data(), A.out()));
  PetscContainer owner = nullptr;
  SNEDE_PETSC(PetscContainerCreate(PETSC_COMM_SELF, &owner));
  SNEDE_PETSC(PetscContainerSetPointer(owner, arrays.get()));
  SNEDE_PETSC(PetscContainerSetUserDestroy(owner, [](void* owned) -> PetscErrorCode {
    delete static_cast<CsrArrays*>(owned);
    return 0;
  }));
  arrays.release();  // the container frees them from now on
  const PetscErrorCode composed =
      PetscObjectCompose(reinterpret_cast<PetscObject>(A.get()), "snede_csr_arrays", reinterpret_cast<PetscObject>(owner));
  PetscContainerDestroy(&owner);  // A holds its own reference
  SNEDE_PETSC(composed);
  return A;
}

}  // namespace snede
