// The friction limit of needle insertion (§6.3.2): after every update no sticking needle node
// carries along the shaft more than its static threshold, and no slipping node more than its
// dynamic one. What a node carries is computed from the model, not from the needle's
// bookkeeping: the elastic force along the shaft, (∇Π + f_ext)·t (∇Π = −f_int − f_ext; for a
// sticking node, which has no friction load, the support's force along the shaft). Tolerance:
// 1e-6 of the largest threshold, far above the solver's rtol 1e-10.
#include <gtest/gtest.h>

#include <cmath>

#include "needle/test_needle_insertion_slab.hpp"

using namespace snede;

TEST(NeedleInsertionFriction, NoNodeCarriesMoreThanItsFrictionThreshold) {
  snede::testing::NeedleSlab slab(20.0, "cpp_needle_friction_");
  std::size_t sticking_seen = 0, slipping_seen = 0;
  for (int update = 0; update < 16; ++update) {
    SCOPED_TRACE(update);
    const NeedleStepResult report = slab.needle.advance(0.5 * snede::testing::slab_edge);
    ASSERT_TRUE(report.converged) << report.reason;
    const std::vector<double> gradient = slab.model.potential_gradient(slab.model.displacement());
    const std::vector<double>& external = slab.model.external_forces();
    double largest = 0;
    for (const NeedleNode& node : slab.needle.needle_nodes()) largest = std::max(largest, node.static_threshold);
    for (const NeedleNode& node : slab.needle.needle_nodes()) {
      const std::size_t x = static_cast<std::size_t>(node.vertex) * 2;  // the shaft runs along +x
      const double carried = std::abs(gradient[x] + external[x]);
      if (node.sticking) {
        ++sticking_seen;
        EXPECT_LE(carried, node.static_threshold + 1e-6 * largest) << "sticking vertex " << node.vertex;
      } else {
        ++slipping_seen;
        EXPECT_LE(carried, node.dynamic_threshold + 1e-6 * largest) << "slipping vertex " << node.vertex;
      }
    }
  }
  EXPECT_GT(sticking_seen, 0u);
  EXPECT_GT(slipping_seen, 0u);
}
