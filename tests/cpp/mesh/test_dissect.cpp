#include <gtest/gtest.h>

#include "fixtures.hpp"
#include "topology/dissect.hpp"
#include "mesh/traversal.hpp"
#include "mesh/validate.hpp"

using namespace snede;
using snede::testing::connectivity_of;
using snede::testing::RecordingWatcher;

namespace {
FaceId face_between(const Connectivity& c, VertexId p, VertexId q) {
  for (FaceId f = 0; f < c.face_capacity(); ++f)
    if (c.is_face(f) && c.face(f).simplex.same_vertices(Simplex(1, {p, q}))) return f;
  return no_id;
}

struct Counter {
  VertexId next;
  VertexId operator()(VertexId) { return next++; }
};
}  // namespace

// Figure 7.6: around v a cut of three edges splits the star into three classes; v is kept
// by one, the other two get new vertices. Here each cut edge also reaches the rim, so the
// rim vertices 1, 4 and 6 split too and the fan falls apart into three pieces.
TEST(Dissect, Figure7_6ThreeClassesAroundAVertex) {
  // Fan of 8 triangles around centre 0 with rim 1..8.
  std::vector<std::vector<VertexId>> fan;
  for (int i = 0; i < 8; ++i) fan.push_back({0, 1 + i, 1 + (i + 1) % 8});
  Connectivity conn = connectivity_of(2, fan);
  RecordingWatcher watcher;
  conn.add_watcher(&watcher);
  const std::vector<FaceId> cut{face_between(conn, 0, 1), face_between(conn, 0, 4), face_between(conn, 0, 6)};
  Counter counter{100};
  const auto split = dissect(conn, cut, std::ref(counter));
  EXPECT_FALSE(find_violation(conn));
  EXPECT_TRUE(watcher.matches(conn));
  ASSERT_EQ(split.size(), 5u);  // centre twice, rim vertices 1, 4, 6 once each
  EXPECT_EQ(split[0].original, 0);
  EXPECT_EQ(split[1].original, 0);
  EXPECT_EQ(split[2].original, 1);
  // three classes of sizes 3, 2, 3 (edges 01, 04, 06 cut the fan of 8)
  std::map<VertexId, int> class_size;
  for (ElementId e : conn.element_ids())
    for (VertexId v : {0, 100, 101})
      if (conn.element(e).simplex.contains(v)) ++class_size[v];
  std::multiset<int> sizes;
  for (auto& entry : class_size) sizes.insert(entry.second);
  EXPECT_EQ(sizes, (std::multiset<int>{2, 3, 3}));
  EXPECT_EQ(connected_components(conn).second, 3);
  EXPECT_EQ(conn.boundary().size(), 8u + 6u);
}

// Figure 7.7: a face of C whose vertices' stars do not split is not dissected.
TEST(Dissect, Figure7_7InteriorEdgeAloneIsNotOpened) {
  const auto cells = snede::testing::grid_triangles(3, 3);
  Connectivity conn = connectivity_of(2, cells);
  // vertices 5 and 10 are interior (4x4 points); edge 5-10 is the diagonal of square (1,1)
  const FaceId edge = face_between(conn, 5, 10);
  ASSERT_NE(edge, no_id);
  const std::vector<FaceId> cut{edge};
  Counter counter{100};
  const auto split = dissect(conn, cut, std::ref(counter));
  EXPECT_TRUE(split.empty());
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.face(edge).mate != no_id, true);
  EXPECT_EQ(conn.boundary().size(), 12u);
}

TEST(Dissect, CutThroughSeparatesAndGlueRestores) {
  // Cut the 2x2x2 Kuhn box along the plane x = 1 (grid index): all faces with vertices of
  // first index 1 only.
  const auto cells = snede::testing::kuhn_box(2);
  Connectivity conn = connectivity_of(3, cells);
  const auto boundary_before = conn.boundary().size();
  RecordingWatcher watcher;
  conn.add_watcher(&watcher);
  std::vector<FaceId> cut;
  for (FaceId f = 0; f < conn.face_capacity(); ++f) {
    const Simplex& s = conn.face(f).simplex;
    bool on_plane = s.sign() > 0 && conn.face(f).mate != no_id;
    for (VertexId v : s.vertices()) on_plane &= v / 9 == 1;
    if (on_plane) cut.push_back(f);
  }
  EXPECT_EQ(cut.size(), 8u);  // 4 squares × 2 triangles
  Counter counter{27};
  const auto split = dissect(conn, cut, std::ref(counter));
  EXPECT_FALSE(find_violation(conn));
  EXPECT_TRUE(watcher.matches(conn));
  EXPECT_EQ(split.size(), 9u);  // every vertex of the plane is duplicated once
  EXPECT_EQ(connected_components(conn).second, 2);
  EXPECT_EQ(conn.boundary().size(), boundary_before + 16u);
  // Glue back: substitute each copy by its original.
  std::map<ElementId, ElementSubstitution> glue;
  for (ElementId e : conn.element_ids())
    for (const SplitVertex& s : split)
      if (conn.element(e).simplex.contains(s.copy)) {
        glue.try_emplace(e, ElementSubstitution{e, {}}).first->second.from_to.emplace_back(s.copy, s.original);
      }
  std::vector<ElementSubstitution> list;
  for (auto& entry : glue) list.push_back(entry.second);
  conn.change_elements(list);
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.boundary().size(), boundary_before);
  EXPECT_EQ(connected_components(conn).second, 1);
  EXPECT_TRUE(watcher.matches(conn));
}

TEST(Dissect, RejectsBoundaryAndMissingFaces) {
  Connectivity conn = connectivity_of(2, {{0, 1, 2}, {1, 3, 2}});
  Counter counter{10};
  const std::vector<FaceId> boundary{face_between(conn, 0, 1)};
  EXPECT_THROW(dissect(conn, boundary, std::ref(counter)), std::invalid_argument);
  const std::vector<FaceId> missing{999};
  EXPECT_THROW(dissect(conn, missing, std::ref(counter)), std::invalid_argument);
}
