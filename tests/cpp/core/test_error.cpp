#include <gtest/gtest.h>

#include <petscvec.h>

#include "core/error.hpp"
#include "core/options.hpp"

TEST(PetscErrors, BecomeExceptionsCarryingPetscsMessage) {
  Vec x = nullptr, y = nullptr;
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, 3, &x));
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, 4, &y));
  PetscScalar dot = 0;
  try {
    SNEDE_PETSC(VecDot(x, y, &dot));
    ADD_FAILURE() << "vectors of different sizes must be rejected";
  } catch (const snede::PetscException& e) {
    EXPECT_NE(e.code(), 0);
    EXPECT_NE(std::string(e.what()).find("VecDot"), std::string::npos) << e.what();
  }
  SNEDE_PETSC(VecDestroy(&x));
  SNEDE_PETSC(VecDestroy(&y));
}

TEST(PetscErrors, OptionValuesAreParsedByPetsc) {
  SNEDE_PETSC(PetscOptionsSetValue(nullptr, "-snede_test_value", "2.5"));
  EXPECT_EQ(snede::option_real("-snede_test_value"), 2.5);
  EXPECT_FALSE(snede::option_real("-snede_test_absent"));
  SNEDE_PETSC(PetscOptionsSetValue(nullptr, "-snede_test_value", "abc"));
  try {
    snede::option_real("-snede_test_value");
    FAIL() << "a non-numeric value must be rejected";
  } catch (const snede::PetscException& e) {
    EXPECT_NE(std::string(e.what()).find("no numeric value"), std::string::npos) << e.what();
  }
}
