// C++ tests initialise and finalise PETSc here, once, around all tests.
#include <gtest/gtest.h>

#include "core/petsc_session.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  snede::PetscSession petsc(&argc, &argv);
  return RUN_ALL_TESTS();
}
