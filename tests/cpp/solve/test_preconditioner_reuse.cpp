// The rule that keeps multigrid levels through several solves (preconditioner_reuse.hpp): kept
// while each solve needs at most refresh_ratio times the CG iterations per Newton iteration of
// the solve that built them; given up after a failure or a slower solve; never kept at ratio 0.
#include <gtest/gtest.h>

#include <stdexcept>

#include "solve/preconditioner_reuse.hpp"

using namespace snede;

TEST(PreconditionerReuse, NothingToKeepBeforeTheFirstSolve) { EXPECT_FALSE(PreconditionerReuse(1.5).keep()); }

TEST(PreconditionerReuse, KeptWhileSolvesStayWithinTheRatioOfTheBuildingSolve) {
  PreconditionerReuse reuse(1.5);
  reuse.record(2, 20, true, true);  // 10 CG per Newton iteration: the baseline
  EXPECT_TRUE(reuse.keep());
  reuse.record(3, 45, true, false);  // 15 = 1.5 × 10: still kept
  EXPECT_TRUE(reuse.keep());
  reuse.record(0, 0, true, false);  // already in equilibrium: says nothing
  EXPECT_TRUE(reuse.keep());
  reuse.record(2, 31, true, false);  // 15.5 > 15
  EXPECT_FALSE(reuse.keep());
  reuse.record(1, 9, true, false);  // a faster solve with the old levels does not revive them
  EXPECT_FALSE(reuse.keep());
  reuse.record(1, 12, true, true);  // new levels: a new baseline
  EXPECT_TRUE(reuse.keep());
}

TEST(PreconditionerReuse, AFailedSolveGivesTheLevelsUp) {
  PreconditionerReuse reuse(3.0);
  reuse.record(1, 5, true, true);
  reuse.record(1, 5, false, false);
  EXPECT_FALSE(reuse.keep());
  reuse.record(4, 40, false, true);  // levels built in a failed solve are not kept either
  EXPECT_FALSE(reuse.keep());
}

TEST(PreconditionerReuse, RatioZeroNeverKeeps) {
  PreconditionerReuse reuse(0.0);
  reuse.record(1, 5, true, true);
  EXPECT_FALSE(reuse.keep());
}

TEST(PreconditionerReuse, ABuildingSolveWithoutCgIterationsCountsAsOne) {
  PreconditionerReuse reuse(1.5);
  reuse.record(1, 0, true, true);
  reuse.record(1, 1, true, false);
  EXPECT_TRUE(reuse.keep());
}

TEST(PreconditionerReuse, RatiosBetweenZeroAndOneOrNotFiniteAreRefused) {
  for (double ratio : {-1.0, 0.5, 0.999, 1.0 / 0.0})
    EXPECT_THROW(PreconditionerReuse{ratio}, std::invalid_argument) << ratio;
  EXPECT_NO_THROW(PreconditionerReuse{1.0});
}
