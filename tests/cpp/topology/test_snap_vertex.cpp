// §3.2 node snapping: a vertex moved onto an edge point when the star stays positive, refused
// (mesh bit for bit unchanged) when an element would turn flat or inside out.
#include <gtest/gtest.h>

#include "topology/edit_checks.hpp"
#include "topology/snap_vertex.hpp"

namespace snede {
namespace {

using namespace snede::testing;

constexpr VertexId kuhn_centre = 13;  // (1, 1, 1) in kuhn_cube(2); (i, j, k) is 9i + 3j + k

// A tetrahedron of the centre's star and its face opposite the centre.
std::vector<VertexId> opposite_face(const Mesh& mesh, VertexId v) {
  const ElementId e = mesh.connectivity().vertex_element(v);
  std::vector<VertexId> face;
  for (VertexId w : mesh.connectivity().element(e).simplex.vertices())
    if (w != v) face.push_back(w);
  return face;
}

// Snapping `v` onto `parents` is refused because an element `would_be` flat or inverted, and
// the mesh stays bit for bit as it was.
void expect_refused(Mesh& mesh, VertexId v, const VertexParents& parents, const std::string& would_be) {
  const MeshSnapshot before(mesh);
  const EditResult result = snap_vertex(mesh, v, parents);
  EXPECT_FALSE(result.done);
  EXPECT_NE(result.reason.find(would_be), std::string::npos) << result.reason;
  EXPECT_EQ(MeshSnapshot(mesh), before);
}

TEST(SnapVertex, OntoAnEdgePointIn3DMovesTheVertexAndItsDisplacement) {
  Mesh mesh = kuhn_cube(2);
  ModelOn physics(mesh);
  const AffineField field(3);
  field.set_on(physics.model, mesh);
  const double energy_density = physics.energy_density(mesh);
  const VertexId w = 22;  // (2, 1, 1)
  const EditResult result = snap_vertex(mesh, kuhn_centre, VertexParents::on_edge(kuhn_centre, w, 0.5));
  ASSERT_TRUE(result.done) << result.reason;
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(coordinates(mesh, kuhn_centre), (std::vector<double>{0.75, 0.5, 0.5}));
  EXPECT_NEAR(total_measure(mesh), 1.0, 1e-15);
  EXPECT_LT(field.deviation(physics.model, mesh), 1e-12);
  EXPECT_NEAR(physics.energy_density(mesh), energy_density, 1e-12 * energy_density);
}

TEST(SnapVertex, OntoAnEdgeMidpointIn2DIsAcceptedOntoTheOppositeEdgeRefused) {
  Mesh mesh = right_triangle_square(2);  // vertex (i, j) is 3i + j; 4 is the centre
  const std::vector<VertexId> ring = neighbours(mesh, 4);
  ASSERT_EQ(ring.size(), 6u);
  // Onto the midpoint of edge (4, 5): half way to a neighbour.
  Mesh accepted = right_triangle_square(2);
  const EditResult done = snap_vertex(accepted, 4, VertexParents::on_edge(4, 5, 0.5));
  ASSERT_TRUE(done.done) << done.reason;
  EXPECT_NO_THROW(accepted.validate());
  EXPECT_EQ(coordinates(accepted, 4), (std::vector<double>{0.5, 0.75}));
  // Onto the midpoint of (5, 8), an edge of the centre's link: its triangle becomes flat.
  expect_refused(mesh, 4, VertexParents::on_edge(5, 8, 0.5), "would be flat");
}

TEST(SnapVertex, OntoOrPastTheOppositeFaceIn3DIsRefusedWithTheMeshUnchanged) {
  Mesh mesh = kuhn_cube(2);
  const std::vector<VertexId> face = opposite_face(mesh, kuhn_centre);
  // The midpoint of an edge of the opposite face: exactly coplanar in doubles.
  expect_refused(mesh, kuhn_centre, VertexParents::on_edge(face[0], face[1], 0.5), "would be flat");
  // Beyond the face's centroid, seen from the centre.
  const std::vector<VertexId> parents{kuhn_centre, face[0], face[1], face[2]};
  const std::vector<double> weights{-0.2, 0.4, 0.4, 0.4};
  expect_refused(mesh, kuhn_centre, VertexParents::barycentric(parents, weights), "would be inverted");
}

TEST(SnapVertex, OnASurfaceAlongAnEdgeIsAcceptedAcrossTheRingRefused) {
  Mesh mesh = bumpy_surface(4, 0.2, 0.0, 1);  // vertex (i, j) is 5i + j; 12 is the centre
  const EditResult along = snap_vertex(mesh, 12, VertexParents::on_edge(12, 13, 0.3));
  ASSERT_TRUE(along.done) << along.reason;
  EXPECT_NO_THROW(mesh.validate());
  // Far beyond neighbour 13: the triangles on the other side fold over.
  expect_refused(mesh, 12, VertexParents::on_edge(12, 13, 3.0), "would be");
}

TEST(SnapVertex, RefusesAVertexThatIsNotInUse) {
  Mesh mesh = right_triangle_square(1);
  const MeshSnapshot before(mesh);
  EXPECT_FALSE(snap_vertex(mesh, 7, VertexParents::copy_of(0)).done);
  EXPECT_EQ(MeshSnapshot(mesh), before);
}

}  // namespace
}  // namespace snede
