// Growable Vecs: a resize keeps the values and zeroes the new entries, reuses the storage while
// it has room and grows it geometrically (so many small appends copy O(total) entries), and a
// handle to an earlier Vec stays valid after the storage moved.
#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "core/error.hpp"
#include "core/growable_vec.hpp"
#include "core/petsc_handle.hpp"
#include "core/petsc_util.hpp"

namespace {

using snede::growable_capacity;
using snede::resize_growable_vec;

// Where v's entries are (VecRestoreArrayRead clears its argument: keep a copy).
const PetscScalar* entries(Vec v) {
  const PetscScalar* data = nullptr;
  SNEDE_PETSC(VecGetArrayRead(v, &data));
  const PetscScalar* where = data;
  SNEDE_PETSC(VecRestoreArrayRead(v, &data));
  return where;
}

}  // namespace

TEST(GrowableVec, ResizesKeepValuesZeroNewEntriesAndKeepTheBlockSize) {
  snede::VecHandle v;
  snede::create_growable_vec(6, 3, v.out());
  EXPECT_EQ(snede::vec_values(v), std::vector<double>(6, 0.0));
  std::vector<double> expected(6);
  std::iota(expected.begin(), expected.end(), 1.0);
  snede::set_vec_values(v, expected);
  for (PetscInt n : {9, 30, 12, 3, 21}) {  // grows, shrinks, grows again over entries once used
    resize_growable_vec(v.slot(), n);
    expected.resize(n, 0.0);
    EXPECT_EQ(snede::vec_values(v), expected) << "size " << n;
    PetscInt block_size = 0;
    SNEDE_PETSC(VecGetBlockSize(v, &block_size));
    EXPECT_EQ(block_size, 3);
    for (double& x : expected) x += 1;
    SNEDE_PETSC(VecShift(v, 1.0));
  }
}

TEST(GrowableVec, ManyAppendsReuseTheStorageAndMoveItLogarithmicallyOften) {
  snede::VecHandle v;
  snede::create_growable_vec(3000, 3, v.out());
  EXPECT_EQ(growable_capacity(v), 3000);
  int moves = 0;
  const PetscScalar* storage = entries(v);
  for (PetscInt n = 3003; n <= 30000; n += 3) {
    const PetscInt capacity = growable_capacity(v);
    resize_growable_vec(v.slot(), n);
    if (entries(v) != storage) {
      ++moves;
      storage = entries(v);
      EXPECT_EQ(growable_capacity(v), capacity + capacity / 2);
    } else {
      EXPECT_EQ(growable_capacity(v), capacity);
    }
    EXPECT_GE(growable_capacity(v), n);
  }
  EXPECT_LE(moves, 6);  // 3000 · 1.5⁶ > 30000
}

TEST(GrowableVec, APlainVecBecomesGrowableAndAnEarlierHandleStaysValid) {
  snede::VecHandle plain;
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, 4, plain.out()));
  SNEDE_PETSC(VecSet(plain, 2.0));
  Vec earlier = plain.get();
  SNEDE_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(earlier)));
  resize_growable_vec(plain.slot(), 5);
  EXPECT_EQ(snede::vec_values(plain), (std::vector<double>{2, 2, 2, 2, 0}));
  EXPECT_GE(growable_capacity(plain), 5);
  EXPECT_EQ(snede::vec_values(earlier), std::vector<double>(4, 2.0));
  SNEDE_PETSC(VecDestroy(&earlier));

  Vec shared = plain.get();
  SNEDE_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(shared)));
  resize_growable_vec(plain.slot(), 1000);  // the storage moves; `shared` keeps the old one
  SNEDE_PETSC(VecSet(plain, 7.0));
  EXPECT_EQ(snede::vec_values(shared), (std::vector<double>{2, 2, 2, 2, 0}));
  SNEDE_PETSC(VecDestroy(&shared));
}
