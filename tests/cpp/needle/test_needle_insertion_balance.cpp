// Force balance of needle insertion (§6.3, §6.7): the slab carries no load but the needle's, so
// after every update the force the needle exerts on the body (support reactions and friction at
// its nodes, needle_forces) is equal and opposite to what the held side's supports exert, up to
// the solver's tolerance (rtol 1e-10 of forces of about 0.1 N, summed over a few hundred
// vertices: far below 1e-6 of the support's force).
#include <gtest/gtest.h>

#include <cmath>

#include "needle/test_needle_insertion_slab.hpp"

using namespace snede;

TEST(NeedleInsertionBalance, TheNeedlesForceOnTheBodyBalancesTheSupport) {
  snede::testing::NeedleSlab slab(20.0, "cpp_needle_balance_");
  for (int update = 0; update < 16; ++update) {
    SCOPED_TRACE(update);
    const NeedleStepResult report = slab.needle.advance(0.5 * snede::testing::slab_edge);
    ASSERT_TRUE(report.converged) << report.reason;
    const std::vector<double> forces = slab.needle.needle_forces();
    ASSERT_EQ(forces.size(), 2 * slab.needle.needle_nodes().size());
    double needle[2] = {0, 0};
    for (std::size_t k = 0; k < forces.size(); ++k) needle[k % 2] += forces[k];
    const std::vector<double> support = slab.support_force();
    const double size = std::hypot(support[0], support[1]);
    if (update > 0) EXPECT_GT(size, 0.0);
    EXPECT_LE(std::hypot(needle[0] + support[0], needle[1] + support[1]), 1e-6 * size);
  }
}
