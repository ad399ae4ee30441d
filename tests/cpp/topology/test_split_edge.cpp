// Edge split (§3.2.3, §7.3): element counts, conserved volume, the new vertex where its
// parents put it, and refusals that leave the mesh bit for bit as it was.
#include <gtest/gtest.h>

#include <limits>

#include "core/predicates.hpp"
#include "topology/edit_checks.hpp"
#include "topology/split_edge.hpp"

namespace snede {
namespace {

using namespace snede::testing;

constexpr VertexId kuhn_centre = 13;    // (1, 1, 1) in kuhn_cube(2)
constexpr VertexId kuhn_x_face = 22;    // (2, 1, 1): the interior edge (13, 22) runs along x

TEST(SplitEdge, InteriorEdgeOfTheKuhnCubeSplitsItsWholeRingAndKeepsTheVolume) {
  Mesh mesh = kuhn_cube(2);
  ModelOn physics(mesh);
  const AffineField field(3);
  field.set_on(physics.model, mesh);
  const std::size_t ring = elements_with_edge(mesh.connectivity(), kuhn_centre, kuhn_x_face).size();
  ASSERT_GE(ring, 3u);
  const std::size_t n_cells = mesh.n_cells();
  const double t = 0.3;
  const EditResult result = split_edge(mesh, kuhn_centre, kuhn_x_face, t);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(mesh.n_cells(), n_cells + ring);
  EXPECT_NEAR(total_measure(mesh), 1.0, 1e-15);
  EXPECT_EQ(elements_with_edge(mesh.connectivity(), kuhn_centre, kuhn_x_face).size(), 0u);
  EXPECT_EQ(elements_with_edge(mesh.connectivity(), kuhn_centre, result.vertex).size(), ring);
  EXPECT_EQ(elements_with_edge(mesh.connectivity(), result.vertex, kuhn_x_face).size(), ring);
  const std::vector<double> expected{(1 - t) * 0.5 + t * 1.0, 0.5, 0.5};
  EXPECT_EQ(coordinates(mesh, result.vertex), expected);
  EXPECT_EQ(mesh.parents(result.vertex).vertex, (std::vector<VertexId>{kuhn_centre, kuhn_x_face}));
  EXPECT_EQ(physics.model.n_dofs(), mesh.n_points() * 3);
  EXPECT_LT(field.deviation(physics.model, mesh), 1e-12);
}

TEST(SplitEdge, BoundaryEdgeIn2DSplitsOneTriangleAndAddsABoundaryEdge) {
  Mesh mesh = right_triangle_square(2);  // vertex (i, j) is 3i + j
  const std::size_t n_faces = mesh.boundary_faces().size() / 2;
  const EditResult result = split_edge(mesh, 0, 3, 0.5);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(mesh.n_cells(), 9u);
  EXPECT_EQ(mesh.boundary_faces().size() / 2, n_faces + 1);
  EXPECT_EQ(total_measure(mesh), 1.0);
}

TEST(SplitEdge, InteriorEdgeOfASurfaceSplitsBothTrianglesAndKeepsTheArea) {
  Mesh mesh = bumpy_surface(4, 0.2, 0.0, 1);  // vertex (i, j) is 5i + j
  const double area = total_measure(mesh);
  const VertexId a = 6, b = 12;  // (1, 1)–(2, 2): a diagonal
  ASSERT_EQ(elements_with_edge(mesh.connectivity(), a, b).size(), 2u);
  const EditResult result = split_edge(mesh, a, b, 0.25);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(mesh.n_cells(), 34u);
  EXPECT_NEAR(total_measure(mesh), area, 1e-14 * area);
  EXPECT_EQ(neighbours(mesh, result.vertex).size(), 4u);
}

TEST(SplitEdge, RefusesBadParametersAndNonEdgesLeavingTheMeshUnchanged) {
  Mesh mesh = kuhn_cube(2);
  const MeshSnapshot before(mesh);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double t : {0.0, 1.0, -0.5, 1.5, nan}) {
    const EditResult result = split_edge(mesh, kuhn_centre, kuhn_x_face, t);
    EXPECT_FALSE(result.done);
    EXPECT_NE(result.reason.find("not in (0, 1)"), std::string::npos) << result.reason;
  }
  // Opposite corners of the cube, an endpoint twice, a vertex that does not exist.
  for (auto [a, b] : {std::pair<VertexId, VertexId>{0, 26}, {kuhn_centre, kuhn_centre}, {kuhn_centre, 99}, {-1, 0}}) {
    const EditResult result = split_edge(mesh, a, b, 0.5);
    EXPECT_FALSE(result.done);
    EXPECT_NE(result.reason.find("not an edge"), std::string::npos) << result.reason;
  }
  EXPECT_EQ(MeshSnapshot(mesh), before);
}

// A triangle whose apex lies one ulp above its long edge (moved there after construction,
// which refuses such slivers). Every split of that edge would leave a half thinner than the
// mesh accepts, and for some t the rounded split point lands beyond the line to the apex, an
// inversion only the exact sign sees: all are refused, the mesh unchanged.
Mesh sliver() {
  Mesh mesh(2, {0.0, 0.0, 1.0, 0.1, 0.5, 0.5}, std::vector<std::int64_t>{0, 1, 2});
  mesh.move_vertex(2, std::vector<double>{0.5, std::nextafter(0.05, 1.0)});
  return mesh;
}

TEST(SplitEdge, RefusesWhenAHalfWouldBeFlatOrInverted) {
  ASSERT_EQ(orientation_2d(sliver().point(0).data(), sliver().point(1).data(), sliver().point(2).data()), 1);
  int n_inverted = 0;
  for (int i = 1; i < 100; ++i) {
    Mesh mesh = sliver();
    const MeshSnapshot before(mesh);
    const EditResult result = split_edge(mesh, 0, 1, i / 100.0);
    ASSERT_FALSE(result.done);
    EXPECT_NE(result.reason.find("would be"), std::string::npos) << result.reason;
    n_inverted += result.reason.find("inverted") != std::string::npos;
    EXPECT_EQ(MeshSnapshot(mesh), before);
  }
  EXPECT_GT(n_inverted, 0);
}

}  // namespace
}  // namespace snede
