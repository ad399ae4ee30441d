// Edge collapse (§3.2.3, Figure 3.10): counts and conserved measures when it is allowed; the
// link condition (with the boundary closed off by a virtual vertex) and flat or inverted
// survivors refuse it, leaving the mesh bit for bit as it was.
#include <gtest/gtest.h>

#include "topology/collapse_edge.hpp"
#include "topology/edit_checks.hpp"

namespace snede {
namespace {

using namespace snede::testing;

void expect_refused(Mesh& mesh, VertexId keep, VertexId gone, double t, const std::string& because) {
  const MeshSnapshot before(mesh);
  const EditResult result = collapse_edge(mesh, keep, gone, t);
  EXPECT_FALSE(result.done);
  EXPECT_NE(result.reason.find(because), std::string::npos) << result.reason;
  EXPECT_EQ(MeshSnapshot(mesh), before);
}

TEST(CollapseEdge, InteriorEdgeIn2DRemovesTwoTrianglesAndKeepsTheArea) {
  Mesh mesh = jittered_square(4, 0.2, 7);  // vertex (i, j) is 5i + j
  ModelOn physics(mesh);
  const AffineField field(2);
  field.set_on(physics.model, mesh);
  const double energy = physics.energy_density(mesh) * total_measure(mesh);
  const VertexId keep = 12, gone = 13;  // (2, 2) and (2, 3), both interior
  const std::vector<double> x_keep = coordinates(mesh, keep), x_gone = coordinates(mesh, gone);
  const double t = 0.5;
  const EditResult result = collapse_edge(mesh, keep, gone, t);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(mesh.n_cells(), 30u);
  EXPECT_FALSE(mesh.is_vertex(gone));
  EXPECT_EQ(coordinates(mesh, keep), (std::vector<double>{0.5 * x_keep[0] + 0.5 * x_gone[0], 0.5 * x_keep[1] + 0.5 * x_gone[1]}));
  EXPECT_NEAR(total_measure(mesh), 1.0, 1e-15);
  EXPECT_EQ(physics.model.n_dofs(), mesh.n_points() * 2);
  EXPECT_LT(field.deviation(physics.model, mesh), 1e-12);
  EXPECT_NEAR(physics.energy_density(mesh) * total_measure(mesh), energy, 1e-12 * energy);
}

TEST(CollapseEdge, BoundaryEdgeIn2DKeepsTheMeshValid) {
  Mesh mesh = right_triangle_square(2);  // vertex (i, j) is 3i + j
  const EditResult result = collapse_edge(mesh, 0, 3);  // along the bottom: (0, 0) ← (1/2, 0)
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(mesh.n_cells(), 7u);
  EXPECT_EQ(total_measure(mesh), 1.0);  // the bottom stays straight
}

TEST(CollapseEdge, Figure310InteriorEdgeBetweenBoundaryVerticesIsRefusedIn2D) {
  // A strip of three squares: every vertex is on the boundary; collapsing the interior edge
  // (1, 0)–(1, 1) would pinch the strip into two triangle fans meeting at one vertex.
  std::vector<double> points;
  for (int i = 0; i <= 3; ++i) points.insert(points.end(), {double(i), 0.0, double(i), 1.0});
  Mesh strip = mesh_of(2, points, grid_triangles(3, 1));  // vertex (i, j) is 2i + j
  expect_refused(strip, 2, 3, 0.0, "link condition");
  expect_refused(strip, 3, 2, 0.5, "link condition");
  // The diagonal of a single square, the smallest such case.
  Mesh square = right_triangle_square(1);
  expect_refused(square, 0, 3, 0.0, "link condition");
  // The edge of a lone triangle: the virtual vertex makes its closure a tetrahedron's surface.
  Mesh triangle(2, {0, 0, 1, 0, 0, 1}, std::vector<std::int64_t>{0, 1, 2});
  expect_refused(triangle, 0, 1, 0.0, "link condition");
}

TEST(CollapseEdge, Figure310AnalogueIn3DTheDiagonalOfAKuhnCubeIsRefused) {
  Mesh cube = kuhn_cube(1);  // the main diagonal (0, 7) is interior, its ends are corners
  ASSERT_EQ(elements_with_edge(cube.connectivity(), 0, 7).size(), 6u);
  expect_refused(cube, 0, 7, 0.0, "link condition");
  expect_refused(cube, 7, 0, 0.5, "link condition");
  Mesh tetrahedron(3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, std::vector<std::int64_t>{0, 1, 2, 3});
  expect_refused(tetrahedron, 0, 1, 0.0, "link condition");
}

TEST(CollapseEdge, RefusesNonEdgesAndBadParameters) {
  Mesh mesh = kuhn_cube(2);
  expect_refused(mesh, 0, 26, 0.0, "not an edge");
  expect_refused(mesh, 13, 13, 0.0, "not an edge");
  expect_refused(mesh, 13, 99, 0.0, "not an edge");
  expect_refused(mesh, 13, 22, -0.1, "not in [0, 1]");
  expect_refused(mesh, 13, 22, 1.1, "not in [0, 1]");
}

// Vertex 0 at the origin and a counter-clockwise ring 1..n around it: triangles (0, i, i+1)
// in 2D; in 3D the same fan made a bipyramid with apexes n+1 = (0, 0, 1), n+2 = (0, 0, −1).
std::vector<std::vector<VertexId>> fan(int n) {
  std::vector<std::vector<VertexId>> cells;
  for (VertexId i = 1; i <= n; ++i) cells.push_back({0, i, i % n + 1});
  return cells;
}

Mesh fan_2d(const std::vector<double>& ring) {
  const int n = static_cast<int>(ring.size() / 2);
  std::vector<double> points{0.0, 0.0};
  points.insert(points.end(), ring.begin(), ring.end());
  return mesh_of(2, points, fan(n));
}

Mesh bipyramid(const std::vector<double>& ring) {
  const int n = static_cast<int>(ring.size() / 2);
  std::vector<double> points{0, 0, 0};
  for (int i = 0; i < n; ++i) points.insert(points.end(), {ring[2 * i], ring[2 * i + 1], 0.0});
  points.insert(points.end(), {0, 0, 1, 0, 0, -1});
  std::vector<std::vector<VertexId>> cells;
  for (const auto& triangle : fan(n)) {
    cells.push_back({triangle[0], triangle[1], triangle[2], n + 1});
    cells.push_back({triangle[0], triangle[2], triangle[1], n + 2});
  }
  return mesh_of(3, points, cells);
}

// A non-convex hexagon: from its vertex 2 = (0, −1) the reflex vertex 4 = (0.2, 0) hides
// edge (4, 5); from vertex 1 = (−1, 0) all of it is visible.
const std::vector<double> dart{-1, 0, 0, -1, 2, -0.2, 0.2, 0, 2, 0.2, 0, 1};
// A hexagon whose edge (4, 5), from (1, 1) to (0, 0.5), lies on a line through vertex 1 = (−1, 0).
const std::vector<double> aligned{-1, 0, 0, -1, 1, -1, 1, 1, 0, 0.5, -1, 1};

// The same fans in 2D (fan_2d) or 3D (bipyramid): from vertex 2 of the dart a survivor would
// be inverted, along the aligned edge one would be flat; from vertex 1 of the dart the collapse
// is allowed and keeps the measure, leaving `cells_after` cells.
void expect_survivors_checked(Mesh (*make)(const std::vector<double>&), std::size_t cells_after) {
  Mesh inverting = make(dart);
  expect_refused(inverting, 2, 0, 0.0, "would be inverted");
  Mesh flattening = make(aligned);
  expect_refused(flattening, 1, 0, 0.0, "would be flat");
  Mesh visible = make(dart);
  const double measure = total_measure(visible);
  const EditResult result = collapse_edge(visible, 1, 0);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(visible.validate());
  EXPECT_EQ(visible.n_cells(), cells_after);
  EXPECT_NEAR(total_measure(visible), measure, 1e-15 * measure);
}

TEST(CollapseEdge, RefusedWhenASurvivorWouldBeInvertedOrFlatIn2D) { expect_survivors_checked(fan_2d, 4u); }

TEST(CollapseEdge, RefusedWhenASurvivorWouldBeInvertedOrFlatIn3D) { expect_survivors_checked(bipyramid, 8u); }

TEST(CollapseEdge, InteriorEdgeIn3DRemovesItsRingAndKeepsTheVolume) {
  Mesh mesh = kuhn_cube(4);  // vertex (i, j, k) is 25i + 5j + k
  ModelOn physics(mesh);
  const AffineField field(3);
  field.set_on(physics.model, mesh);
  const double energy = physics.energy_density(mesh);
  const VertexId keep = 62, gone = 63;  // (2, 2, 2) and (2, 2, 3)
  const std::size_t ring = elements_with_edge(mesh.connectivity(), keep, gone).size();
  const std::size_t n_cells = mesh.n_cells();
  const EditResult result = collapse_edge(mesh, keep, gone, 0.5);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(mesh.n_cells(), n_cells - ring);
  EXPECT_NEAR(total_measure(mesh), 1.0, 1e-14);
  EXPECT_EQ(coordinates(mesh, keep), (std::vector<double>{0.5, 0.5, 0.625}));
  EXPECT_LT(field.deviation(physics.model, mesh), 1e-12);
  EXPECT_NEAR(physics.energy_density(mesh), energy, 1e-12 * energy);
}

TEST(CollapseEdge, OnASurfaceInteriorEdgeAcceptedRimToRimRefused) {
  Mesh mesh = bumpy_surface(4, 0.2, 0.0, 1);  // vertex (i, j) is 5i + j
  expect_refused(mesh, 15, 21, 0.0, "link condition");  // (3, 0)–(4, 1) cuts off the corner (4, 0)
  const EditResult result = collapse_edge(mesh, 12, 13, 0.5);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(mesh.n_cells(), 30u);
  EXPECT_FALSE(mesh.is_vertex(13));
}

}  // namespace
}  // namespace snede
