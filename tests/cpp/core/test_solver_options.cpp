#include <gtest/gtest.h>

#include <petscksp.h>

#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/solver_options.hpp"

namespace {

// The KSP type and maximum iterations a KSP with prefix "opt_" gets from `options`.
std::pair<std::string, PetscInt> configured_ksp(const snede::SolverOptions& options) {
  KSP ksp = nullptr;
  SNEDE_PETSC(KSPCreate(PETSC_COMM_SELF, &ksp));
  options.use_for(ksp);
  SNEDE_PETSC(KSPSetOptionsPrefix(ksp, "opt_"));
  SNEDE_PETSC(KSPSetFromOptions(ksp));
  KSPType type = nullptr;
  PetscInt max_it = 0;
  SNEDE_PETSC(KSPGetType(ksp, &type));
  SNEDE_PETSC(KSPGetTolerances(ksp, nullptr, nullptr, nullptr, &max_it));
  std::pair<std::string, PetscInt> result{type, max_it};
  SNEDE_PETSC(KSPDestroy(&ksp));
  return result;
}

}  // namespace

TEST(SolverOptions, ReachOnlyTheirOwnSolverAndNeverTheGlobalDatabase) {
  const snede::SolverOptions first("opt_", {{"ksp_type", "cg"}, {"-ksp_max_it", "7"}});
  const snede::SolverOptions second("opt_", {});
  EXPECT_EQ(configured_ksp(first), std::make_pair(std::string(KSPCG), PetscInt{7}));
  EXPECT_EQ(configured_ksp(second), std::make_pair(std::string(KSPGMRES), PetscInt{10000}));
  PetscBool set = PETSC_TRUE;
  SNEDE_PETSC(PetscOptionsHasName(nullptr, nullptr, "-opt_ksp_type", &set));
  EXPECT_FALSE(set);
}

TEST(SolverOptions, TheGlobalDatabaseWinsAndIsMarkedUsedWhenRead) {
  SNEDE_PETSC(PetscOptionsSetValue(nullptr, "-opt_ksp_max_it", "3"));
  const snede::SolverOptions options("opt_", {{"ksp_max_it", "7"}});
  EXPECT_EQ(configured_ksp(options).second, 3);
  PetscBool used = PETSC_TRUE;
  SNEDE_PETSC(PetscOptionsUsed(nullptr, "opt_ksp_max_it", &used));
  EXPECT_FALSE(used);
  options.mark_read_options_used();
  SNEDE_PETSC(PetscOptionsUsed(nullptr, "opt_ksp_max_it", &used));
  EXPECT_TRUE(used);
  SNEDE_PETSC(PetscOptionsClearValue(nullptr, "-opt_ksp_max_it"));
}

TEST(SolverOptions, BadNamesAreRejectedWithTheName) {
  for (const std::string name : {"", "--", "ksp max_it"}) {
    try {
      snede::SolverOptions options("opt_", {{name, "1"}});
      ADD_FAILURE() << "the name '" << name << "' must be rejected";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("'" + name + "'"), std::string::npos) << e.what();
    }
  }
}

TEST(SolverOptions, NumbersAreReadWholeOrRefusedWithTheOption) {
  const snede::SolverOptions options("opt_", {{"width", "2.5"}, {"ratio", "1e-3"}, {"bad", "2.5x"}, {"word", "wide"}});
  EXPECT_EQ(options.number_option("opt_width", 7.0), 2.5);
  EXPECT_EQ(options.number_option("opt_ratio", 7.0), 1e-3);
  EXPECT_EQ(options.number_option("opt_absent", 7.0), 7.0);
  for (const std::string name : {"opt_bad", "opt_word"}) {
    try {
      options.number_option(name, 0.0);
      ADD_FAILURE() << name << " must be refused";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("-" + name + " must be a number"), std::string::npos) << e.what();
    }
  }
}
