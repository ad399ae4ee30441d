#include "core/csr_matrix.hpp"

#include <stdexcept>
#include <string>

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

CsrView::CsrView(Mat A) : A_(A) {
  PetscBool aij = PETSC_FALSE, baij = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATSEQAIJ, &aij));
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATSEQBAIJ, &baij));
  if (!aij && !baij) {
    MatType type = nullptr;
    SNEDE_PETSC(MatGetType(A, &type));
    throw std::logic_error(std::string("in-place CSR access needs a SeqAIJ or SeqBAIJ matrix, not ") + type);
  }
  blocked = baij;
  PetscBool done = PETSC_FALSE;
  // Unshifted and unsymmetrised: PETSc's own row starts and columns, not copies.
  SNEDE_PETSC(MatGetRowIJ(A_, 0, PETSC_FALSE, blocked ? PETSC_TRUE : PETSC_FALSE, &rows, &start, &column, &done));
  if (!done) throw std::logic_error("the matrix gave no rows");
  if (blocked) {
    SNEDE_PETSC(MatSeqBAIJGetArray(A_, &value));
  } else {
    SNEDE_PETSC(MatSeqAIJGetArray(A_, &value));
  }
}

CsrView::~CsrView() {
  if (blocked) {
    MatSeqBAIJRestoreArray(A_, &value);
  } else {
    MatSeqAIJRestoreArray(A_, &value);
  }
  PetscBool done = PETSC_FALSE;
  MatRestoreRowIJ(A_, 0, PETSC_FALSE, blocked ? PETSC_TRUE : PETSC_FALSE, &rows, &start, &column, &done);
}

}  // namespace snede
