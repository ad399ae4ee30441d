// Hand-made cases from the thesis's figures (a, b, c, d, ... = 0, 1, 2, 3, ...).
#include <gtest/gtest.h>

#include "fixtures.hpp"
#include "mesh/connectivity.hpp"
#include "mesh/validate.hpp"

using namespace snede;
using snede::testing::connectivity_of;
using snede::testing::RecordingWatcher;

namespace {
constexpr VertexId a = 0, b = 1, c = 2, d = 3;

FaceId face_with(const Connectivity& conn, const Simplex& s) {
  for (FaceId f = 0; f < conn.face_capacity(); ++f)
    if (conn.is_face(f) && conn.face(f).simplex == s) return f;
  return no_id;
}
}  // namespace

TEST(Connectivity, Figure7_2TwoTriangles) {
  // T = {abc, bdc}: boundary {ab, ca, bd, dc}; bc and cb are a matched pair.
  const Connectivity conn = connectivity_of(2, {{a, b, c}, {b, d, c}});
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.n_elements(), 2u);
  EXPECT_EQ(conn.n_faces(), 6u);
  std::set<Simplex> boundary;
  for (const auto& entry : conn.boundary()) boundary.insert(entry.first);
  EXPECT_EQ(boundary, (std::set<Simplex>{Simplex(1, {a, b}), Simplex(1, {c, a}), Simplex(1, {b, d}),
                                         Simplex(1, {d, c})}));
  const FaceId bc = face_with(conn, Simplex(1, {b, c}));
  const FaceId cb = face_with(conn, Simplex(1, {c, b}));
  ASSERT_NE(bc, no_id);
  ASSERT_NE(cb, no_id);
  EXPECT_EQ(conn.face(bc).mate, cb);
  EXPECT_EQ(conn.face(cb).mate, bc);
  EXPECT_EQ(conn.opposite_vertex(conn.face(bc).element, bc), a);
  EXPECT_EQ(conn.opposite_face(0, a), bc);
  EXPECT_EQ(conn.neighbor(0, 0), 1);
}

TEST(Connectivity, FromCellsRejectsNonManifoldAndOverlaps) {
  // three triangles on edge 01
  EXPECT_THROW(connectivity_of(2, {{0, 1, 2}, {1, 0, 3}, {1, 0, 4}}), std::invalid_argument);
  // two triangles on the same side of edge 01
  EXPECT_THROW(connectivity_of(2, {{0, 1, 2}, {0, 1, 3}}), std::invalid_argument);
  // the same cell twice
  EXPECT_THROW(connectivity_of(2, {{0, 1, 2}, {1, 2, 0}}), std::invalid_argument);
}

TEST(Connectivity, Figure7_4EdgeFlipReusesOuterFacesAndLeavesBoundaryAlone) {
  // Quad a b c d (counter-clockwise) split by diagonal bd: {bcd, abd} -> {abc, acd}.
  Connectivity conn = connectivity_of(2, {{b, c, d}, {a, b, d}});
  RecordingWatcher watcher;
  conn.add_watcher(&watcher);
  const FaceId ab = face_with(conn, Simplex(1, {a, b})), bc = face_with(conn, Simplex(1, {b, c}));
  const FaceId cd = face_with(conn, Simplex(1, {c, d})), da = face_with(conn, Simplex(1, {d, a}));
  struct Probe : ConnectivityWatcher {
    ConnectivityChange last;
    void init(const Connectivity&) override {}
    void on_change(const Connectivity&, const ConnectivityChange& change) override { last = change; }
  } probe;
  conn.add_watcher(&probe);
  const std::vector<ElementId> old{0, 1};
  const std::vector<Simplex> flipped{Simplex(1, {a, b, c}), Simplex(1, {a, c, d})};
  const auto added = conn.replace_elements(old, flipped);
  EXPECT_FALSE(find_violation(conn));
  ASSERT_EQ(added.size(), 2u);
  // The four outer faces are the same objects, now pointing to the new elements.
  EXPECT_EQ(face_with(conn, Simplex(1, {a, b})), ab);
  EXPECT_EQ(face_with(conn, Simplex(1, {b, c})), bc);
  EXPECT_EQ(face_with(conn, Simplex(1, {c, d})), cd);
  EXPECT_EQ(face_with(conn, Simplex(1, {d, a})), da);
  EXPECT_EQ(conn.face(ab).element, added[0]);
  EXPECT_EQ(conn.face(cd).element, added[1]);
  // The new diagonal is a matched pair that never touched the boundary.
  EXPECT_TRUE(probe.last.boundary_added.empty());
  EXPECT_TRUE(probe.last.boundary_removed.empty());
  const FaceId ac = face_with(conn, Simplex(1, {a, c}));
  ASSERT_NE(ac, no_id);
  EXPECT_EQ(conn.face(conn.face(ac).mate).simplex, Simplex(1, {c, a}));
  EXPECT_EQ(face_with(conn, Simplex(1, {b, d})), no_id);
  EXPECT_EQ(probe.last.removed_elements.size(), 2u);
  EXPECT_TRUE(watcher.matches(conn));
}

TEST(Connectivity, RemovingAndAddingExposesAndCoversBoundary) {
  Connectivity conn = connectivity_of(2, {{a, b, c}, {b, d, c}});
  RecordingWatcher watcher;
  conn.add_watcher(&watcher);
  const std::vector<ElementId> remove{1};
  conn.replace_elements(remove, {});
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.boundary().size(), 3u);
  EXPECT_TRUE(conn.boundary().count(Simplex(1, {b, c})));
  EXPECT_TRUE(watcher.matches(conn));
  const std::vector<Simplex> back{Simplex(1, {b, d, c})};
  conn.replace_elements({}, back);
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.boundary().size(), 4u);
  EXPECT_TRUE(watcher.matches(conn));
}

TEST(Connectivity, RemovingBothElementsOfAMatchedPairLeavesNoStaleFaceInTheBoundary) {
  // abc, bdc and a third triangle cde: removing the first two discards the pair bc/cb.
  constexpr VertexId e = 4;
  Connectivity conn = connectivity_of(2, {{a, b, c}, {b, d, c}, {c, d, e}});
  RecordingWatcher watcher;
  conn.add_watcher(&watcher);
  const std::vector<ElementId> remove{0, 1};
  conn.replace_elements(remove, {});
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.boundary().size(), 3u);
  EXPECT_TRUE(conn.boundary().count(Simplex(1, {c, d})));  // cde's face, no longer matched
  EXPECT_TRUE(watcher.matches(conn));
}

TEST(Connectivity, ReplaceElementsRejectsBadCallsWithoutChangingAnything) {
  Connectivity conn = connectivity_of(2, {{a, b, c}, {b, d, c}});
  const std::vector<ElementId> dead{5}, twice{0, 0}, none{};
  EXPECT_THROW(conn.replace_elements(dead, {}), std::invalid_argument);
  EXPECT_THROW(conn.replace_elements(twice, {}), std::invalid_argument);
  // wrong dimension
  const std::vector<Simplex> edge{Simplex(1, {a, d})};
  EXPECT_THROW(conn.replace_elements(none, edge), std::invalid_argument);
  // abc again (its faces exist, Figure 7.8 caught through the boundary face ab)
  const std::vector<Simplex> again{Simplex(1, {a, b, c})};
  EXPECT_THROW(conn.replace_elements(none, again), std::invalid_argument);
  // a triangle on the other side of bc would duplicate the interior face cb... it is caught
  // through the mate of the old face when bdc is among the removed elements:
  const std::vector<ElementId> first{0};
  const std::vector<Simplex> overlapping{Simplex(1, {c, b, 4})};
  EXPECT_THROW(conn.replace_elements(first, overlapping), std::invalid_argument);
  // two new simplexes sharing an oriented face
  const std::vector<Simplex> clash{Simplex(1, {a, d, 4}), Simplex(1, {a, d, 5})};
  EXPECT_THROW(conn.replace_elements(none, clash), std::invalid_argument);
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.n_elements(), 2u);
}

TEST(Connectivity, ChangeElementsCutsAndStitchesKeepingObjects) {
  // Figure 7.5 idea: a fan of four triangles around vertex 4 (centre); substituting the centre
  // by a copy in two of them opens a cut; substituting back stitches it closed again.
  //   3---2
  //   | \ |      triangles 041, 142, 243, 340 around centre 4
  //   0---1
  Connectivity conn = connectivity_of(2, {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
  RecordingWatcher watcher;
  conn.add_watcher(&watcher);
  const auto faces_before = conn.element(0).faces;
  const std::vector<ElementSubstitution> cut{{0, {{4, 5}}}, {1, {{4, 5}}}};
  conn.change_elements(cut);
  EXPECT_FALSE(find_violation(conn));
  EXPECT_TRUE(watcher.matches(conn));
  EXPECT_EQ(conn.element(0).simplex, Simplex(1, {0, 1, 5}));
  // The same Face objects, renamed (object identity kept).
  std::set<FaceId> before(faces_before.begin(), faces_before.begin() + 3);
  std::set<FaceId> after(conn.element(0).faces.begin(), conn.element(0).faces.begin() + 3);
  EXPECT_EQ(before, after);
  // The cut opened edges 4-0 / 5-0 and 4-2 / 5-2: 4 more boundary edges.
  EXPECT_EQ(conn.boundary().size(), 8u);
  const std::vector<ElementSubstitution> stitch{{0, {{5, 4}}}, {1, {{5, 4}}}};
  conn.change_elements(stitch);
  EXPECT_FALSE(find_violation(conn));
  EXPECT_EQ(conn.boundary().size(), 4u);
  EXPECT_TRUE(watcher.matches(conn));
}

TEST(Connectivity, ChangeElementsRejectsNonInjectiveSubstitution) {
  Connectivity conn = connectivity_of(2, {{0, 1, 2}});
  const std::vector<ElementSubstitution> collapse{{0, {{0, 1}}}};
  EXPECT_THROW(conn.change_elements(collapse), std::invalid_argument);
  const std::vector<ElementSubstitution> dead{{3, {{0, 5}}}};
  EXPECT_THROW(conn.change_elements(dead), std::invalid_argument);
  EXPECT_FALSE(find_violation(conn));
}

TEST(Connectivity, WatcherIsInitialisedWithCurrentState) {
  const auto cells = snede::testing::kuhn_box(2);
  Connectivity conn = connectivity_of(3, cells);
  RecordingWatcher watcher;
  conn.add_watcher(&watcher);
  EXPECT_EQ(watcher.elements.size(), 48u);
  EXPECT_EQ(watcher.boundary.size(), 2u * 6u * 4u);  // 6 sides × 4 squares × 2 triangles
  EXPECT_TRUE(watcher.matches(conn));
  conn.remove_watcher(&watcher);
  const std::vector<ElementId> one{0};
  conn.replace_elements(one, {});
  EXPECT_EQ(watcher.n_changes, 0);
}

TEST(Validate, ReportsTheViolatedInvariant) {
  // A valid mesh passes; tampering is only possible through the public API's preconditions,
  // so check that a hand-broken copy (via a simplex of the wrong orientation in a stitched
  // change that the checks cannot see, Figure 7.8) is reported with its invariant number.
  Connectivity conn = connectivity_of(2, {{a, b, c}, {b, d, c}});
  EXPECT_FALSE(find_violation(conn));
  // Add abc' where c' = 7: shares the interior edge... we add a triangle with face "bc"
  // already interior (it belongs to abc and its mate cb to bdc): not caught by the cheap
  // checks of replace_elements when no old element is given (Figure 7.8).
  const std::vector<Simplex> duplicate{Simplex(1, {b, c, 7})};
  conn.replace_elements({}, duplicate);
  const auto violation = find_violation(conn);
  ASSERT_TRUE(violation);
  EXPECT_NE(violation->find("(7.4)"), std::string::npos) << *violation;
}
