// A sequential PETSc matrix as a dense Eigen matrix, for tests that compare interpolations
// entry by entry.
#pragma once

#include <petscmat.h>

#include <Eigen/Dense>

#include "core/error.hpp"

namespace snede::testing {

inline Eigen::MatrixXd dense_matrix(Mat A) {
  PetscInt rows = 0, columns = 0;
  SNEDE_PETSC(MatGetSize(A, &rows, &columns));
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(rows, columns);
  for (PetscInt r = 0; r < rows; ++r) {
    PetscInt n = 0;
    const PetscInt* at = nullptr;
    const PetscScalar* values = nullptr;
    SNEDE_PETSC(MatGetRow(A, r, &n, &at, &values));
    for (PetscInt k = 0; k < n; ++k) dense(r, at[k]) = values[k];
    SNEDE_PETSC(MatRestoreRow(A, r, &n, &at, &values));
  }
  return dense;
}

}  // namespace snede::testing
