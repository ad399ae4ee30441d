// The bisection hierarchy (§6.5): a BSP tree over the refined mesh, kept by watching the
// connectivity (§7.4).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

#include "mesh/traversal.hpp"
#include "topology/dissect.hpp"
#include "topology/refine_around.hpp"
#include "topology/random_editor.hpp"
#include "topology/refinement_checks.hpp"

namespace snede {
namespace {

using namespace snede::testing;

// The live elements containing x, by a scan with barycentric coordinates (no tree).
std::vector<ElementId> containing_by_scan(const Mesh& mesh, const std::vector<double>& x) {
  std::vector<ElementId> found;
  const int d = mesh.dim();
  for (ElementId e : mesh.cell_ids()) {
    const std::vector<double> corners = mesh.corners(e);
    // Sub-volumes with x replacing each corner in turn: all ≥ 0 iff x is in the element.
    const double whole = signed_volume(d, corners);
    bool inside = true;
    for (int i = 0; i <= d; ++i) {
      std::vector<double> replaced = corners;
      std::copy(x.begin(), x.end(), replaced.begin() + i * d);
      inside = inside && signed_volume(d, replaced) >= -1e-10 * whole;
    }
    if (inside) found.push_back(e);
  }
  return found;
}

double label_volume(const Mesh& mesh, const TaggedSimplex& label) {
  std::vector<double> corners;
  for (int i = 0; i <= label.dim; ++i) {
    const auto x = coordinates(mesh, label.vertex[i]);
    corners.insert(corners.end(), x.begin(), x.end());
  }
  return std::abs(signed_volume(mesh.dim(), corners));
}

TEST(RefinementHierarchy, LocatesRandomPointsLikeAScan) {
  Mesh mesh = kuhn_cube(2);
  Bisection bisection(mesh);
  refine_around(bisection, std::vector<double>{0.2, 0.7, 0.4}, 0.05);
  bisection.refine_uniform(1);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const std::vector<double> x{coordinate(random), coordinate(random), coordinate(random)};
    EXPECT_EQ(bisection.hierarchy().locate_all(x), containing_by_scan(mesh, x));
  }
  const std::vector<double> vertex{0.5, 0.5, 0.0}, outside{0.5, 0.5, -0.01};
  EXPECT_EQ(bisection.hierarchy().locate_all(vertex), containing_by_scan(mesh, vertex));
  EXPECT_EQ(bisection.hierarchy().locate(outside), no_id);
}

// The roots whose label simplex contains x, by a scan of all roots: what roots_containing
// did before it had a grid (barycentric coordinates at the current coordinates, ≥ −1e-10).
std::vector<NodeId> roots_by_scan(const Mesh& mesh, const RefinementHierarchy& tree, const std::vector<double>& x) {
  std::vector<NodeId> found;
  for (NodeId r : tree.roots()) {
    const TaggedSimplex& label = tree.node(r).label;
    const std::vector<double> x0 = coordinates(mesh, label.vertex[0]);
    Eigen::Matrix3d edges;
    Eigen::Vector3d offset;
    for (int k = 0; k < 3; ++k) {
      for (int i = 1; i <= 3; ++i) edges(k, i - 1) = coordinates(mesh, label.vertex[i])[k] - x0[k];
      offset(k) = x[k] - x0[k];
    }
    const Eigen::Vector3d mu = edges.partialPivLu().solve(offset);
    if (std::min({1 - mu.sum(), mu(0), mu(1), mu(2)}) >= -1e-10) found.push_back(r);
  }
  return found;
}

// Point location finds the roots near x through a grid over their boxes, kept through edits:
// new roots join it, moved or reused vertices make it stale. After every edit of a random
// sequence (snaps move vertices, collapses free ids that splits reuse) and of a sequence of
// dissections alone (new roots, no vertex moved: the grid is kept and grows), it finds the roots
// a scan finds; refine_around's locations in between keep the grid in use.
TEST(RefinementHierarchy, FindsTheRootsAScanFindsThroughRandomEdits) {
  std::mt19937 random(8);
  std::uniform_real_distribution<double> coordinate(-0.05, 1.05), interior(0.3, 0.7);
  std::size_t n_found = 0;
  for (const bool only_dissections : {false, true}) {
    Mesh mesh = shuffled_jittered_cube(3, 0.2, 7);
    RandomEditor editor(mesh, 7);
    const RefinementHierarchy& tree = editor.bisector().hierarchy();
    for (int step = 0; step < 300; ++step) {
      if (step % 25 == 0)
        refine_around(editor.bisector(), std::vector<double>{interior(random), 0.5, 0.5}, 0.1);
      else
        editor.edit(only_dissections ? dissection : editor.choose(static_cast<double>(mesh.n_cells()) / 162));
      for (int i = 0; i < 5; ++i) {
        const std::vector<double> x{coordinate(random), coordinate(random), coordinate(random)};
        const std::vector<NodeId> expected = roots_by_scan(mesh, tree, x);
        ASSERT_EQ(tree.roots_containing(x), expected) << "after step " << step << (only_dissections ? " of dissections" : "");
        n_found += expected.size();
      }
    }
  }
  EXPECT_GT(n_found, 2000u);
}

TEST(RefinementHierarchy, ChildrenHalveTheirParentAndLeavesAreTheElements) {
  Mesh mesh = right_triangle_square(3);
  Bisection bisection(mesh);
  refine_around(bisection, std::vector<double>{0.61, 0.23}, 0.01);
  const RefinementHierarchy& tree = bisection.hierarchy();
  std::size_t n_leaves = 0;
  for (NodeId n = 0; n < static_cast<NodeId>(tree.n_nodes()); ++n) {
    const RefinementNode& node = tree.node(n);
    if (node.is_leaf()) {
      ++n_leaves;
      ASSERT_NE(node.element, no_id);
      EXPECT_EQ(tree.node_of(node.element), n);
      EXPECT_TRUE(Simplex(1, std::span<const VertexId>(node.label.vertex.data(), 3))
                      .same_vertices(mesh.connectivity().element(node.element).simplex));
      continue;
    }
    const double whole = label_volume(mesh, node.label);
    for (NodeId child : node.children) {
      EXPECT_EQ(tree.node(child).parent, n);
      EXPECT_NEAR(label_volume(mesh, tree.node(child).label), whole / 2, 1e-15);
    }
  }
  EXPECT_EQ(n_leaves, mesh.n_cells());
  EXPECT_EQ(tree.n_nodes(), 2 * mesh.n_cells() - tree.roots().size());
}

TEST(RefinementHierarchy, FollowsChangesMadeByOtherOperations) {
  Mesh mesh = right_triangle_square(2);
  Bisection bisection(mesh);
  bisection.refine_uniform(1);
  // Cut along an interior edge of the element at (0.2, 0.05); both its ends are on the
  // boundary, so the cut duplicates vertices: a change_elements the hierarchy did not announce.
  const ElementId e = bisection.hierarchy().locate(std::vector<double>{0.2, 0.05});
  const Simplex& s = mesh.connectivity().element(e).simplex;
  std::vector<VertexId> interior_face;
  for (int j = 0; j <= 2 && interior_face.empty(); ++j)
    if (mesh.connectivity().neighbor(e, j) != no_id)
      for (VertexId v : s.subn(j).vertices()) interior_face.push_back(v);
  const VertexId n_points_before = mesh.n_points();
  dissect(mesh, interior_face);
  EXPECT_GT(mesh.n_points(), n_points_before);
  for (ElementId live : mesh.cell_ids())
    for (VertexId v : mesh.connectivity().element(live).simplex.vertices())
      EXPECT_TRUE(bisection.hierarchy().label(live).contains(v));
  EXPECT_GT(bisection.refine_uniform(1), 0u);
  EXPECT_NO_THROW(mesh.validate());
}

}  // namespace
}  // namespace snede
