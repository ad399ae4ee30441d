// §5.3.1 vertex removal by retriangulating the star with ears (Figure 5.10).
#include <gtest/gtest.h>

#include <cmath>

#include "topology/edit_checks.hpp"
#include "topology/flip_edge.hpp"
#include "topology/remove_vertex.hpp"

namespace snede {
namespace {

using namespace snede::testing;

void expect_refused(Mesh& mesh, VertexId v, const std::string& reason_part) {
  const MeshSnapshot before(mesh);
  const EditResult result = remove_vertex_by_flips(mesh, v);
  EXPECT_FALSE(result.done);
  EXPECT_NE(result.reason.find(reason_part), std::string::npos) << result.reason;
  EXPECT_TRUE(MeshSnapshot(mesh) == before);
}

// Vertex 0 at `centre`, ring vertices 1..n at `ring` (counter-clockwise), a closed fan.
Mesh fan(std::vector<double> centre, const std::vector<std::vector<double>>& ring) {
  std::vector<double> points = centre;
  std::vector<std::vector<VertexId>> cells;
  const auto n = static_cast<VertexId>(ring.size());
  for (VertexId i = 0; i < n; ++i) {
    points.insert(points.end(), ring[i].begin(), ring[i].end());
    cells.push_back({0, i + 1, (i + 1) % n + 1});
  }
  return mesh_from(2, static_cast<int>(centre.size()), points, cells);
}

void expect_all_interior_edges_delaunay(const Mesh& mesh) {
  const std::vector<VertexId> cells = mesh.cells();
  for (std::size_t i = 0; i < cells.size(); i += 3)
    for (int j = 0; j < 3; ++j) EXPECT_TRUE(is_locally_delaunay(mesh, cells[i + j], cells[i + (j + 1) % 3]));
}

TEST(RemoveVertexByFlips, RegularHexagonFanBecomesFourTriangles) {
  std::vector<std::vector<double>> ring;
  for (int k = 0; k < 6; ++k) ring.push_back({std::cos(k * M_PI / 3), std::sin(k * M_PI / 3)});
  Mesh hexagon = fan({0, 0}, ring);
  RecordingWatcher watcher;
  hexagon.connectivity().add_watcher(&watcher);
  const double area = total_measure(hexagon);
  EXPECT_NEAR(area, 3 * std::sqrt(3.0) / 2, 1e-15);
  const EditResult result = remove_vertex_by_flips(hexagon, 0);
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_EQ(hexagon.n_cells(), 4u);
  EXPECT_FALSE(hexagon.is_vertex(0));
  EXPECT_EQ(hexagon.n_live_points(), 6);
  EXPECT_NO_THROW(hexagon.validate());
  EXPECT_NEAR(total_measure(hexagon), area, 1e-15);
  EXPECT_EQ(hexagon.boundary_faces().size(), 6u * 2);
  EXPECT_EQ(watcher.n_changes, 1);  // the new triangles and the removed vertex, one change
  EXPECT_TRUE(watcher.matches(hexagon.connectivity()));
  hexagon.connectivity().remove_watcher(&watcher);
}

TEST(RemoveVertexByFlips, NonConvexLinkIsTriangulatedInsideConvexLinkDelaunay) {
  // A star whose link has a reflex vertex (ring vertex 3 at (0, 0.5)) and a long flat side.
  Mesh star = fan({0, 0.2}, {{-1, -1}, {1, -1}, {1, 1}, {0, 0.5}, {-1, 1}});
  const double area = total_measure(star);
  ASSERT_TRUE(remove_vertex_by_flips(star, 0).done);
  EXPECT_EQ(star.n_cells(), 3u);
  EXPECT_NO_THROW(star.validate());
  EXPECT_NEAR(total_measure(star), area, 1e-15);
  // A convex link gets its Delaunay triangulation.
  Mesh convex = fan({0.1, 0.1}, {{0, -1}, {3, -0.2}, {3, 0.2}, {0, 1}, {-0.3, 0}});
  ASSERT_TRUE(remove_vertex_by_flips(convex, 0).done);
  EXPECT_NO_THROW(convex.validate());
  expect_all_interior_edges_delaunay(convex);
}

TEST(RemoveVertexByFlips, BoundaryVertexBetweenCollinearNeighboursIsRemoved) {
  // 2 × 1 squares; vertex 2 = (1, 0) on the bottom side, between (0, 0) and (2, 0).
  Mesh strip = mesh_from(2, 2, {0, 0, 0, 1, 1, 0, 1, 1, 2, 0, 2, 1}, grid_triangles(2, 1));
  const double area = total_measure(strip);
  ASSERT_TRUE(remove_vertex_by_flips(strip, 2).done);
  EXPECT_NO_THROW(strip.validate());
  EXPECT_EQ(strip.n_cells(), 3u);
  EXPECT_NEAR(total_measure(strip), area, 1e-15);
  // The corners are not straight between their boundary neighbours.
  expect_refused(strip, 0, "straight");
  expect_refused(strip, 5, "straight");
}

TEST(RemoveVertexByFlips, RefusesABoundaryVertexWithNonCollinearNeighbours) {
  // Vertex 2 lifted to (1, −0.01): a corner of the boundary, however slight.
  Mesh strip = mesh_from(2, 2, {0, 0, 0, 1, 1, -0.01, 1, 1, 2, 0, 2, 1}, grid_triangles(2, 1));
  expect_refused(strip, 2, "straight");
}

TEST(RemoveVertexByFlips, WorksOnClosedSurfacesUnlessTheResultWouldDuplicateATriangle) {
  // Octahedron: removing the top leaves a square of four link vertices to triangulate.
  Mesh octahedron = mesh_from(2, 3, {1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1},
                              {{4, 0, 1}, {4, 1, 2}, {4, 2, 3}, {4, 3, 0}, {5, 1, 0}, {5, 2, 1}, {5, 3, 2}, {5, 0, 3}});
  ASSERT_NO_THROW(octahedron.validate());
  ASSERT_TRUE(remove_vertex_by_flips(octahedron, 4).done);
  EXPECT_EQ(octahedron.n_cells(), 6u);
  EXPECT_NO_THROW(octahedron.validate());
  EXPECT_TRUE(octahedron.boundary_faces().empty());
  // Vertex 5's link is the same square; one of its diagonals is free: a doubly covered square.
  ASSERT_TRUE(remove_vertex_by_flips(octahedron, 5).done);
  EXPECT_EQ(octahedron.n_cells(), 4u);
  EXPECT_NO_THROW(octahedron.validate());
  // Now every link is a triangle that already exists.
  for (VertexId v = 0; v < 4; ++v) expect_refused(octahedron, v, "already exists");
  // The tetrahedron's surface would become two copies of one triangle.
  Mesh tetrahedron = mesh_from(2, 3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
  expect_refused(tetrahedron, 3, "already exists");
}

TEST(RemoveVertexByFlips, RejectsTetrahedraAndDeadVertices) {
  Mesh hexagon = fan({0, 0}, {{1, 0}, {0, 1}, {-1, 0}, {0, -1}});
  EXPECT_THROW(remove_vertex_by_flips(hexagon, 9), std::invalid_argument);
  Mesh tetrahedron = mesh_from(3, 3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, {{0, 1, 2, 3}});
  EXPECT_THROW(remove_vertex_by_flips(tetrahedron, 0), std::invalid_argument);
}

}  // namespace
}  // namespace snede
