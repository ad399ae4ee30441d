// A sequential AIJ matrix over CSR arrays that snede fills itself (an assembled tangent, a
// Galerkin product): PETSc takes the arrays as they are, without inserting them row by row, and
// the matrix owns them, so that they live as long as it does — a petsc4py handle or a PC may
// keep the matrix after the object that made it is gone.
#pragma once

#include <petscmat.h>

#include <memory>
#include <vector>

#include "core/petsc_handle.hpp"

namespace snede {

struct CsrArrays {
  std::vector<PetscInt> row_start, columns;  // each row's columns sorted
  std::vector<PetscScalar> values;
};

// A rows × columns SeqAIJ matrix over `arrays`, which it frees when it is destroyed. The arrays
// (reachable through the pointer kept before the move) stay valid while the matrix lives; values
// written into them in place count once the matrix is assembled again.
MatHandle matrix_owning(std::unique_ptr<CsrArrays> arrays, PetscInt rows, PetscInt columns);

}  // namespace snede
