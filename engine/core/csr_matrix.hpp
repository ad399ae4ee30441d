// A sequential AIJ matrix over CSR arrays that snede fills itself (an assembled tangent, a
// Galerkin product): PETSc takes the arrays as they are, without inserting them row by row, and
// the matrix owns them, so that they live as long as it does — a petsc4py handle or a PC may
// keep the matrix after the object that made it is gone. And in-place access to the arrays of
// any sequential AIJ or BAIJ matrix.
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

// A SeqAIJ or SeqBAIJ matrix's own arrays for the duration of a scope, to read or write in
// place (written values count once the matrix is assembled again): each row's start and
// columns, block rows and block columns for SeqBAIJ, whose values hold each block column by
// column. Throws std::logic_error for another type.
class CsrView {
 public:
  explicit CsrView(Mat A);
  ~CsrView();
  CsrView(const CsrView&) = delete;
  CsrView& operator=(const CsrView&) = delete;

  bool blocked = false;  // SeqBAIJ
  PetscInt rows = 0;     // block rows for SeqBAIJ
  const PetscInt* start = nullptr;
  const PetscInt* column = nullptr;
  PetscScalar* value = nullptr;

 private:
  Mat A_;
};

}  // namespace snede
