#include "core/petsc_session.hpp"

#include "core/error.hpp"

namespace snede {

PetscSession::PetscSession(int* argc, char*** argv) {
  SNEDE_PETSC(PetscInitialize(argc, argv, nullptr, nullptr));
  // Errors are returned to check_petsc and thrown, never printed-and-aborted.
  SNEDE_PETSC(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
}

PetscSession::~PetscSession() {
  PetscPopErrorHandler();
  PetscFinalize();
}

}  // namespace snede
