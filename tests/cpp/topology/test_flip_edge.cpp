// §5.2.2 edge flips in 2D and on surfaces (§5.3.1, Figure 5.9), and the empty-circle test.
#include <gtest/gtest.h>

#include <set>

#include "topology/edit_checks.hpp"
#include "topology/flip_edge.hpp"

namespace snede {
namespace {

using namespace snede::testing;

std::set<std::set<VertexId>> vertex_sets(const Mesh& mesh) {
  std::set<std::set<VertexId>> sets;
  const std::vector<VertexId> cells = mesh.cells();
  for (std::size_t i = 0; i < cells.size(); i += 3) sets.insert({cells[i], cells[i + 1], cells[i + 2]});
  return sets;
}

void expect_refused(Mesh& mesh, VertexId a, VertexId b, const std::string& reason_part) {
  const MeshSnapshot before(mesh);
  const EditResult result = flip_edge(mesh, a, b);
  EXPECT_FALSE(result.done);
  EXPECT_NE(result.reason.find(reason_part), std::string::npos) << result.reason;
  EXPECT_TRUE(MeshSnapshot(mesh) == before);
}

// Quadrilateral a = 0, b = 1 (the edge), c = 2 on its left, d = 3 on its right.
Mesh quadrilateral(std::vector<double> c, std::vector<double> d) {
  return mesh_from(2, 2, {0, 0, 1, 0, c[0], c[1], d[0], d[1]}, {{0, 1, 2}, {1, 0, 3}});
}

TEST(FlipEdge, FlipsTheDiagonalOfASquare) {
  Mesh square = mesh_from(2, 2, {0, 0, 1, 0, 1, 1, 0, 1}, {{0, 1, 2}, {0, 2, 3}});
  RecordingWatcher watcher;
  square.connectivity().add_watcher(&watcher);
  const EditResult result = flip_edge(square, 0, 2);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_EQ(vertex_sets(square), (std::set<std::set<VertexId>>{{0, 1, 3}, {1, 2, 3}}));
  EXPECT_NO_THROW(square.validate());
  EXPECT_DOUBLE_EQ(total_measure(square), 1.0);
  EXPECT_EQ(watcher.n_changes, 1);
  EXPECT_TRUE(watcher.matches(square.connectivity()));
  // Flipping back restores the first diagonal.
  ASSERT_TRUE(flip_edge(square, 1, 3).done);
  EXPECT_EQ(vertex_sets(square), (std::set<std::set<VertexId>>{{0, 1, 2}, {0, 2, 3}}));
  square.connectivity().remove_watcher(&watcher);
}

TEST(FlipEdge, RefusesBoundaryAndMissingEdges) {
  Mesh square = mesh_from(2, 2, {0, 0, 1, 0, 1, 1, 0, 1}, {{0, 1, 2}, {0, 2, 3}});
  expect_refused(square, 0, 1, "lies on the boundary");
  expect_refused(square, 1, 3, "does not exist");
  expect_refused(square, 1, 1, "does not exist");
  expect_refused(square, 1, 17, "does not exist");
}

TEST(FlipEdge, RefusesANonConvexQuadrilateral) {
  // At b = (1, 0) the quadrilateral (a, d, b, c) turns clockwise: (b, c, d) would be inverted.
  Mesh reflex = quadrilateral({0.5, 1}, {1.5, -0.1});
  expect_refused(reflex, 0, 1, "inverted");
  // c, b, d on one line: (b, c, d) would be degenerate.
  Mesh straight = quadrilateral({0.5, 1}, {1.5, -1});
  expect_refused(straight, 0, 1, "degenerate");
}

TEST(FlipEdge, RefusesAFlipThatDuplicatesAnEdgeLikeFigure59) {
  // The closed surface of a tetrahedron: the other diagonal of every edge's quadrilateral is
  // already an edge, so the flip would make two triangles with the same three corners.
  Mesh tetrahedron = mesh_from(2, 3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
  ASSERT_NO_THROW(tetrahedron.validate());
  for (auto [a, b] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{2, 3}}) expect_refused(tetrahedron, a, b, "already exists");
}

TEST(FlipEdge, FlipsOnASurfaceAndRefusesAFoldOver) {
  // The quadrilaterals above lifted onto the tilted plane z = x.
  Mesh tilted_square = mesh_from(2, 3, {0, 0, 0, 1, 0, 1, 1, 1, 1, 0, 1, 0}, {{0, 1, 2}, {0, 2, 3}});
  ASSERT_TRUE(flip_edge(tilted_square, 0, 2).done);
  EXPECT_NO_THROW(tilted_square.validate());
  EXPECT_NEAR(total_measure(tilted_square), std::sqrt(2.0), 1e-15);

  Mesh reflex = mesh_from(2, 3, {0, 0, 0, 1, 0, 1, 0.5, 1, 0.5, 1.5, -0.1, 1.5}, {{0, 1, 2}, {1, 0, 3}});
  expect_refused(reflex, 0, 1, "fold over");
  Mesh straight = mesh_from(2, 3, {0, 0, 0, 1, 0, 1, 0.5, 1, 0.5, 1.5, -1, 1.5}, {{0, 1, 2}, {1, 0, 3}});
  expect_refused(straight, 0, 1, "degenerate");
}

TEST(FlipEdge, LocalDelaunayCriterionAgreesWithTheCircumcircle) {
  // abc = (0,0), (1,0), (0.5,0.2): circumcentre (0.5, −0.525), radius 0.725. d = (0.5, −1) is
  // 0.475 from the centre, inside: (a, b) is illegal. d = (0.5, −1.3) is 0.775 away: legal.
  Mesh illegal = quadrilateral({0.5, 0.2}, {0.5, -1});
  EXPECT_FALSE(is_locally_delaunay(illegal, 0, 1));
  EXPECT_FALSE(is_locally_delaunay(illegal, 1, 0));
  EXPECT_TRUE(is_locally_delaunay(illegal, 0, 2));  // boundary edge
  ASSERT_TRUE(flip_edge(illegal, 0, 1).done);
  EXPECT_TRUE(is_locally_delaunay(illegal, 2, 3));  // §5.2.1: the flipped diagonal is legal

  Mesh legal = quadrilateral({0.5, 0.2}, {0.5, -1.3});
  EXPECT_TRUE(is_locally_delaunay(legal, 0, 1));
  // The cocircular case counts as legal for both diagonals of a square.
  Mesh square = mesh_from(2, 2, {0, 0, 1, 0, 1, 1, 0, 1}, {{0, 1, 2}, {0, 2, 3}});
  EXPECT_TRUE(is_locally_delaunay(square, 0, 2));
  ASSERT_TRUE(flip_edge(square, 0, 2).done);
  EXPECT_TRUE(is_locally_delaunay(square, 1, 3));
  EXPECT_THROW(is_locally_delaunay(square, 0, 2), std::invalid_argument);
}

TEST(FlipEdge, LocalDelaunayCriterionFromEitherTriangleAgreesWithTheEdgeLookUp) {
  for (const double depth : {-1.0, -1.3}) {
    const Mesh mesh = quadrilateral({0.5, 0.2}, {0.5, depth});
    const Connectivity& c = mesh.connectivity();
    for (ElementId e = 0; e < c.element_capacity(); ++e) {
      if (!c.is_element(e)) continue;
      const auto v = c.element(e).simplex.vertices();
      for (int j = 0; j < 3; ++j) {
        const VertexId a = v[j], b = v[(j + 1) % 3];
        EXPECT_EQ(is_locally_delaunay(mesh, e, a, b), is_locally_delaunay(mesh, a, b)) << "edge " << a << "-" << b;
        EXPECT_EQ(is_locally_delaunay(mesh, e, b, a), is_locally_delaunay(mesh, a, b));
      }
    }
    // The diagonal (0, 1) from both of its triangles: illegal for the deep-inside d only.
    for (ElementId e : {0, 1}) EXPECT_EQ(is_locally_delaunay(mesh, e, 0, 1), depth < -1.2);
    EXPECT_THROW(is_locally_delaunay(mesh, 0, 2, 3), std::invalid_argument);  // not an edge of element 0
    EXPECT_THROW(is_locally_delaunay(mesh, 7, 0, 1), std::invalid_argument);  // no such element
  }
}

}  // namespace
}  // namespace snede
