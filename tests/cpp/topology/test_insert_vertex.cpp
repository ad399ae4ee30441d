// Vertex insertion in a cell (1→3 triangles, 1→4 tetrahedra) and on a face (2→6 tetrahedra).
#include <gtest/gtest.h>

#include <map>

#include "topology/edit_checks.hpp"
#include "topology/insert_vertex.hpp"

namespace snede {
namespace {

using namespace snede::testing;

// Weights in the order of e's oriented vertices, from a weight per vertex id (0 if absent).
std::vector<double> weights_in(const Mesh& mesh, ElementId e, const std::map<VertexId, double>& by_vertex) {
  const Simplex& s = mesh.connectivity().element(e).simplex;
  const auto oriented = s.oriented_vertices();
  std::vector<double> weights;
  for (int i = 0; i < s.count(); ++i) weights.push_back(by_vertex.count(oriented[i]) ? by_vertex.at(oriented[i]) : 0.0);
  return weights;
}

void expect_refused(Mesh& mesh, ElementId e, const std::vector<double>& weights, const std::string& reason_part) {
  const MeshSnapshot before(mesh);
  const EditResult result = insert_vertex(mesh, e, weights);
  EXPECT_FALSE(result.done);
  EXPECT_NE(result.reason.find(reason_part), std::string::npos) << result.reason;
  EXPECT_TRUE(MeshSnapshot(mesh) == before);
}

Mesh unit_tetrahedron() { return mesh_from(3, 3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, {{0, 1, 2, 3}}); }

TEST(InsertVertex, SplitsATetrahedronIntoFourWhoseVolumesAreTheWeights) {
  Mesh mesh = unit_tetrahedron();
  const std::map<VertexId, double> by_vertex{{0, 0.1}, {1, 0.2}, {2, 0.3}, {3, 0.4}};
  RecordingWatcher watcher;
  mesh.connectivity().add_watcher(&watcher);
  const EditResult result = insert_vertex(mesh, 0, weights_in(mesh, 0, by_vertex));
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_EQ(result.vertex, 4);
  EXPECT_EQ(mesh.n_cells(), 4u);
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_NEAR(total_measure(mesh), 1.0 / 6, 1e-16);
  // The piece without corner v is the original with v moved to the new point: volume w_v·V.
  for (ElementId e : mesh.cell_ids()) {
    const Simplex& s = mesh.connectivity().element(e).simplex;
    for (const auto& [v, w] : by_vertex)
      if (!s.contains(v)) EXPECT_NEAR(mesh.measure(e), w / 6, 1e-16);
  }
  EXPECT_DOUBLE_EQ(mesh.point(4)[0], 0.2);
  EXPECT_DOUBLE_EQ(mesh.point(4)[1], 0.3);
  EXPECT_DOUBLE_EQ(mesh.point(4)[2], 0.4);
  EXPECT_EQ(mesh.parents(4).count(), 4u);
  EXPECT_EQ(watcher.n_changes, 1);
  EXPECT_TRUE(watcher.matches(mesh.connectivity()));
  mesh.connectivity().remove_watcher(&watcher);
}

TEST(InsertVertex, OnAFaceSplitsBothTetrahedraIntoThree) {
  Mesh mesh = mesh_from(3, 3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.3, 0.3, -1}, {{0, 1, 2, 3}, {0, 2, 1, 4}});
  const double volume = total_measure(mesh);
  const ElementId e = mesh.cell_ids()[0];
  const EditResult result = insert_vertex(mesh, e, weights_in(mesh, e, {{0, 0.2}, {1, 0.3}, {2, 0.5}}));
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_EQ(mesh.n_cells(), 6u);
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_NEAR(total_measure(mesh), volume, 1e-15);
  EXPECT_EQ(mesh.parents(result.vertex).count(), 3u);  // the face's corners only
  EXPECT_EQ(mesh.boundary_faces().size(), 6u * 3);     // the shared face stays interior
  // On a boundary face only the one tetrahedron is split.
  Mesh single = unit_tetrahedron();
  ASSERT_TRUE(insert_vertex(single, 0, weights_in(single, 0, {{1, 0.2}, {2, 0.3}, {3, 0.5}})).done);
  EXPECT_EQ(single.n_cells(), 3u);
  EXPECT_NO_THROW(single.validate());
  EXPECT_EQ(single.boundary_faces().size(), 6u * 3);
}

TEST(InsertVertex, SplitsATriangleInThePlaneAndOnASurface) {
  Mesh plane = mesh_from(2, 2, {0, 0, 2, 0, 0, 1}, {{0, 1, 2}});
  ASSERT_TRUE(insert_vertex(plane, 0, std::vector<double>{0.2, 0.3, 0.5}).done);
  EXPECT_EQ(plane.n_cells(), 3u);
  EXPECT_NO_THROW(plane.validate());
  EXPECT_NEAR(total_measure(plane), 1.0, 1e-15);

  Mesh surface = mesh_from(2, 3, {0, 0, 0, 2, 0, 1, 0, 1, 1}, {{0, 1, 2}});
  const double area = total_measure(surface);
  ASSERT_TRUE(insert_vertex(surface, 0, std::vector<double>{0.2, 0.3, 0.5}).done);
  EXPECT_EQ(surface.n_cells(), 3u);
  EXPECT_NO_THROW(surface.validate());
  EXPECT_NEAR(total_measure(surface), area, 1e-15);
}

TEST(InsertVertex, RefusesPointsOnEdgesAndVerticesAndTooCloseToASide) {
  Mesh triangle = mesh_from(2, 2, {0, 1, 1, 1, 0, 2}, {{0, 1, 2}});
  expect_refused(triangle, 0, weights_in(triangle, 0, {{0, 0.5}, {1, 0.5}}), "split_edge");
  expect_refused(triangle, 0, weights_in(triangle, 0, {{2, 1.0}}), "is vertex 2");
  // 0.5·1 + 0.5·1 + 1e-17·2 rounds to y = 1: the point lands exactly on edge (0, 1).
  expect_refused(triangle, 0, weights_in(triangle, 0, {{0, 0.5}, {1, 0.5}, {2, 1e-17}}), "too close");

  Mesh tetrahedron = unit_tetrahedron();
  expect_refused(tetrahedron, 0, weights_in(tetrahedron, 0, {{0, 0.5}, {3, 0.5}}), "split_edge");
  expect_refused(tetrahedron, 0, weights_in(tetrahedron, 0, {{3, 1.0}}), "is vertex 3");
}

TEST(InsertVertex, RejectsWeightsThatAreNotBarycentric) {
  Mesh mesh = unit_tetrahedron();
  const MeshSnapshot before(mesh);
  EXPECT_THROW(insert_vertex(mesh, 0, std::vector<double>{0.5, 0.5, 0.0}), std::invalid_argument);
  EXPECT_THROW(insert_vertex(mesh, 0, std::vector<double>{0.5, 0.5, 0.5, -0.5}), std::invalid_argument);
  EXPECT_THROW(insert_vertex(mesh, 0, std::vector<double>{0.5, 0.5, 0.5, 0.5}), std::invalid_argument);
  EXPECT_THROW(insert_vertex(mesh, 0, std::vector<double>{NAN, 0.5, 0.5, 0.0}), std::invalid_argument);
  EXPECT_THROW(insert_vertex(mesh, 3, std::vector<double>{0.25, 0.25, 0.25, 0.25}), std::invalid_argument);
  EXPECT_TRUE(MeshSnapshot(mesh) == before);
}

}  // namespace
}  // namespace snede
