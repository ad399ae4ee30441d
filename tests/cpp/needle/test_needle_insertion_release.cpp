// Release past the tip (§6.3.2): a load along the shaft on every vertex (5 mN each, about 5 N in
// all: enough to drag the nodes near the tip past it, not all of them; 1 mN drags none past)
// pulls the slab over the needle; the needle nodes that slide past the tip leave the needle and
// are free vertices again (no constraint, so no reaction), and the needle keeps the others.
#include <gtest/gtest.h>

#include <set>

#include "needle/test_needle_insertion_slab.hpp"

using namespace snede;

TEST(NeedleInsertionRelease, NodesDraggedPastTheTipAreReleasedAndFree) {
  snede::testing::NeedleSlab slab(0.5, "cpp_needle_release_");
  slab.insert(0.03, snede::testing::slab_edge);
  std::set<VertexId> before;
  for (const NeedleNode& node : slab.needle.needle_nodes()) before.insert(node.vertex);
  ASSERT_GT(before.size(), 3u);
  std::vector<VertexId> every(slab.mesh.n_points());
  for (VertexId v = 0; v < slab.mesh.n_points(); ++v) every[v] = v;
  slab.model.add_nodal_force("push", every, std::vector<double>{0.005, 0.0});
  const NeedleStepResult report = slab.needle.settle();
  ASSERT_TRUE(report.converged) << report.reason;
  EXPECT_GT(report.released, 0);
  std::set<VertexId> after;
  for (const NeedleNode& node : slab.needle.needle_nodes()) after.insert(node.vertex);
  EXPECT_FALSE(after.empty());
  const std::vector<double> u = vec_values(slab.model.displacement());
  std::size_t released = 0;
  for (VertexId v : before) {
    if (after.count(v)) continue;
    ++released;
    EXPECT_GT(slab.mesh.point(v)[0] + u[v * 2], slab.needle.depth()) << "vertex " << v << " released before the tip";
    EXPECT_EQ(slab.model.constraints()[v].kind, ConstraintKind::free) << "vertex " << v;
  }
  EXPECT_EQ(released, static_cast<std::size_t>(report.released));
}
