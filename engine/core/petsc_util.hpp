// Small PETSc conveniences shared by the solvers.
#pragma once

#include <petsctime.h>
#include <petscvec.h>

#include "core/error.hpp"

namespace snede {

inline double vec_norm(Vec v) {
  PetscReal norm = 0;
  SNEDE_PETSC(VecNorm(v, NORM_2, &norm));
  return norm;
}

inline double wall_seconds() {
  PetscLogDouble t = 0;
  SNEDE_PETSC(PetscTime(&t));
  return t;
}

inline double logged_flops() {
  PetscLogDouble flops = 0;
  SNEDE_PETSC(PetscGetFlops(&flops));
  return flops;
}

// Bytes currently allocated through PetscMalloc: tracked only when PETSc runs with
// -malloc_debug (or -malloc_view); 0 otherwise.
inline double petsc_allocated_bytes() {
  PetscLogDouble bytes = 0;
  SNEDE_PETSC(PetscMallocGetCurrentUsage(&bytes));
  return bytes;
}

}  // namespace snede
