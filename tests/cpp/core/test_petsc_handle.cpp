// The owning PETSc handles: they release their object on every path (scope exit, out(),
// reset, move), and a destroy that fails is reported and counted, never ignored.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"

namespace {

PetscInt references(Vec v) {
  PetscInt count = 0;
  SNEDE_PETSC(PetscObjectGetReference(reinterpret_cast<PetscObject>(v), &count));
  return count;
}

// A Vec held by the handle and by the test: the handle's release shows as one reference fewer.
Vec shared_vec(snede::VecHandle& handle) {
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, 3, handle.out()));
  SNEDE_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(handle.get())));
  return handle.get();
}

PetscErrorCode destroy_then_fail(Vec* v) {
  VecDestroy(v);
  return PETSC_ERR_LIB;
}

}  // namespace

TEST(PetscHandle, ReleasesItsObjectAtScopeExitOnResetAndOnOut) {
  Vec kept = nullptr;
  {
    snede::VecHandle handle;
    kept = shared_vec(handle);
    EXPECT_EQ(references(kept), 2);
  }
  EXPECT_EQ(references(kept), 1);
  snede::VecHandle handle(kept);  // takes over the test's reference
  Vec replaced = nullptr;
  SNEDE_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(kept)));
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, 2, handle.out()));  // out() released `kept` first
  EXPECT_EQ(references(kept), 1);
  replaced = handle.get();
  EXPECT_NE(replaced, kept);
  handle.reset();
  EXPECT_FALSE(handle);
  SNEDE_PETSC(VecDestroy(&kept));
}

TEST(PetscHandle, MovesOwnershipWithoutADoubleDestroy) {
  snede::VecHandle first;
  Vec v = shared_vec(first);
  snede::VecHandle second(std::move(first));
  EXPECT_FALSE(first);
  EXPECT_EQ(second.get(), v);
  snede::VecHandle third;
  third = std::move(second);
  EXPECT_EQ(references(v), 2);
  third.reset();
  EXPECT_EQ(references(v), 1);
  SNEDE_PETSC(VecDestroy(&v));
}

TEST(PetscHandle, ReleasesWhatAThrowingConstructionMade) {
  Vec kept = nullptr;
  struct TwoVectors {
    snede::VecHandle a, b;
    explicit TwoVectors(Vec& kept) {
      kept = shared_vec(a);
      SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, 3, b.out()));
      throw std::invalid_argument("a bad option, found after both were made");
    }
  };
  EXPECT_THROW(TwoVectors{kept}, std::invalid_argument);
  EXPECT_EQ(references(kept), 1);
  SNEDE_PETSC(VecDestroy(&kept));
}

TEST(PetscHandle, AFailedDestroyIsReportedAndCounted) {
  const long before = snede::destroy_failures();
  {
    snede::PetscHandle<Vec, destroy_then_fail> handle;
    SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, 3, handle.out()));
    testing::internal::CaptureStderr();
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(snede::destroy_failures(), before + 1);
  EXPECT_NE(printed.find("destroying a PETSc Vec failed"), std::string::npos) << printed;
}
