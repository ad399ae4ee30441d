// The rule that keeps multigrid levels through Newton iterations and solves
// (preconditioner_reuse.hpp): kept while each Newton iteration's CG needs at most refresh_ratio
// times the CG iterations of the first one after the levels were filled; given up after a failed
// linear solve or solve, or a slower iteration; at ratio 0 kept through one solve only.
#include <gtest/gtest.h>

#include <stdexcept>

#include "solvers/preconditioner_reuse.hpp"

using namespace snede;

TEST(PreconditionerReuse, NothingToKeepBeforeTheFirstFill) { EXPECT_FALSE(PreconditionerReuse(1.5).keep()); }

TEST(PreconditionerReuse, KeptWhileIterationsStayWithinTheRatioOfTheFirstAfterTheFill) {
  PreconditionerReuse reuse(1.5);
  reuse.filled(true);
  EXPECT_TRUE(reuse.keep());
  reuse.record_linear_solve(10, true);  // the baseline
  reuse.record_linear_solve(15, true);  // 1.5 × 10: still kept
  reuse.record_solve(true);
  EXPECT_TRUE(reuse.keep());
  reuse.record_linear_solve(16, true);  // > 15, in the next solve
  EXPECT_FALSE(reuse.keep());
  reuse.record_linear_solve(9, true);  // a faster iteration with the old levels does not revive them
  reuse.record_solve(true);
  EXPECT_FALSE(reuse.keep());
  reuse.filled(true);  // filled again: a new baseline
  EXPECT_TRUE(reuse.keep());
  reuse.record_linear_solve(20, true);
  reuse.record_linear_solve(30, true);
  EXPECT_TRUE(reuse.keep());
}

TEST(PreconditionerReuse, LevelsRefilledOnEarlierConstraintsKeepTheirBaseline) {
  PreconditionerReuse reuse(2.0);
  reuse.filled(true);
  reuse.record_linear_solve(5, true);
  reuse.filled(false);  // the constraints changed; the interpolation is the earlier one
  reuse.record_linear_solve(10, true);  // 2 × 5: kept
  EXPECT_TRUE(reuse.keep());
  reuse.record_linear_solve(11, true);
  EXPECT_FALSE(reuse.keep());
}

TEST(PreconditionerReuse, AFailedLinearSolveOrSolveGivesTheLevelsUp) {
  PreconditionerReuse reuse(3.0);
  reuse.filled(true);
  reuse.record_linear_solve(5, true);
  reuse.record_linear_solve(5, false);
  EXPECT_FALSE(reuse.keep());
  reuse.filled(true);
  reuse.record_linear_solve(5, true);
  reuse.record_solve(false);  // levels filled in a failed solve are not kept either
  EXPECT_FALSE(reuse.keep());
}

TEST(PreconditionerReuse, RatioZeroKeepsTheLevelsThroughOneSolveOnly) {
  PreconditionerReuse reuse(0.0);
  reuse.filled(true);
  reuse.record_linear_solve(5, true);
  reuse.record_linear_solve(50, true);
  EXPECT_TRUE(reuse.keep());
  reuse.record_solve(true);
  EXPECT_FALSE(reuse.keep());
}

TEST(PreconditionerReuse, ABaselineWithoutCgIterationsCountsAsOne) {
  PreconditionerReuse reuse(1.5);
  reuse.filled(true);
  reuse.record_linear_solve(0, true);
  reuse.record_linear_solve(1, true);
  EXPECT_TRUE(reuse.keep());
  reuse.record_linear_solve(2, true);
  EXPECT_FALSE(reuse.keep());
}

TEST(PreconditionerReuse, RatiosBetweenZeroAndOneOrNotFiniteAreRefused) {
  for (double ratio : {-1.0, 0.5, 0.999, 1.0 / 0.0})
    EXPECT_THROW(PreconditionerReuse{ratio}, std::invalid_argument) << ratio;
  EXPECT_NO_THROW(PreconditionerReuse{1.0});
}
