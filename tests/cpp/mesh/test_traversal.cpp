#include <gtest/gtest.h>

#include <set>

#include "fixtures.hpp"
#include "mesh/traversal.hpp"

using namespace snede;
using snede::testing::connectivity_of;

namespace {
// Brute force: ids of all elements whose simplex contains every vertex of s.
std::set<ElementId> containing(const Connectivity& c, const Simplex& s) {
  std::set<ElementId> out;
  for (ElementId e : c.element_ids())
    if (c.element(e).simplex.contains_all(s)) out.insert(e);
  return out;
}
}  // namespace

TEST(Traversal, CycleAroundInteriorEdgeOfKuhnBoxIsTheWholeRingInOrder) {
  const Connectivity conn = connectivity_of(3, snede::testing::kuhn_box(2));
  int interior_edges_checked = 0;
  for (ElementId e : conn.element_ids()) {
    const Element& element = conn.element(e);
    for (int face_index = 0; face_index <= 3; ++face_index) {
      const FaceId entry = element.faces[face_index];
      for (int j = 0; j < 3; ++j) {
        const Simplex edge = conn.face(entry).simplex.subn(j);
        const auto ring = cycle_around(conn, entry, j);
        const std::set<ElementId> expected = containing(conn, edge);
        EXPECT_EQ(std::set<ElementId>(ring.begin(), ring.end()), expected) << edge.to_string();
        EXPECT_EQ(ring.size(), expected.size()) << "no element twice";
        // consecutive elements of the ring are neighbours
        for (std::size_t i = 1; i < ring.size(); ++i) {
          bool adjacent = false;
          for (int k = 0; k <= 3; ++k) adjacent |= conn.neighbor(ring[i - 1], k) == ring[i];
          EXPECT_TRUE(adjacent);
        }
        ++interior_edges_checked;
      }
    }
  }
  EXPECT_EQ(interior_edges_checked, 48 * 4 * 3);
}

TEST(Traversal, CycleAroundVertexIn2DOnBoundaryAndInside) {
  const Connectivity conn = connectivity_of(2, snede::testing::grid_triangles(2, 2));
  // vertex 4 is the centre of the 3x3 grid of points: 6 triangles around it; vertex 1 is on
  // the boundary (3 triangles).
  for (VertexId v : {4, 1, 0}) {
    const std::set<ElementId> expected = containing(conn, Simplex(1, {v}));
    for (ElementId e : expected) {
      const Element& element = conn.element(e);
      for (int face_index = 0; face_index <= 2; ++face_index) {
        const Simplex& face = conn.face(element.faces[face_index]).simplex;
        const int j = face.index(v) == 0 ? 1 : 0;  // remove the other vertex to keep v
        if (!face.contains(v)) continue;
        const auto ring = cycle_around(conn, element.faces[face_index], j);
        EXPECT_EQ(std::set<ElementId>(ring.begin(), ring.end()), expected) << "vertex " << v;
      }
    }
  }
  EXPECT_EQ(containing(conn, Simplex(1, {4})).size(), 6u);
}

TEST(Traversal, VertexStarMatchesBruteForce) {
  const Connectivity conn = connectivity_of(3, snede::testing::kuhn_box(2));
  for (VertexId v = 0; v < 27; ++v) {
    const auto star = vertex_star(conn, v);
    EXPECT_EQ(std::set<ElementId>(star.begin(), star.end()), containing(conn, Simplex(1, {v}))) << v;
  }
  EXPECT_EQ(vertex_star(conn, 13).size(), 24u);  // centre of the Kuhn box: 24 tetrahedra
  EXPECT_TRUE(vertex_star(conn, 99).empty());
}

TEST(Traversal, BoundaryFacesAndComponents) {
  const Connectivity conn = connectivity_of(2, {{0, 1, 2}, {1, 3, 2}, {10, 11, 12}});
  const auto faces = boundary_faces(conn);
  EXPECT_EQ(faces.size(), 7u);
  for (std::size_t i = 1; i < faces.size(); ++i) EXPECT_LT(conn.face(faces[i - 1]).simplex, conn.face(faces[i]).simplex);
  const auto [label, n] = connected_components(conn);
  EXPECT_EQ(n, 2);
  EXPECT_EQ(label[0], label[1]);
  EXPECT_NE(label[0], label[2]);
}
