// PETSc lifetime for C++ programs and tests. Python code never uses this: there,
// petsc4py initialises PETSc once when snede is imported.
#pragma once

namespace snede {

class PetscSession {
 public:
  PetscSession(int* argc, char*** argv);
  ~PetscSession();
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
};

}  // namespace snede
