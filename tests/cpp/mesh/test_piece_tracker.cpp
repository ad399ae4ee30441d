// PieceTracker against connected_components (a full O(n) count, independent of the local
// search): after random dissections of plane sections of Kuhn boxes, partial and complete,
// interleaved with edge splits that add elements, the piece count and the partition the
// labels define must equal the full count's; and a cut that separates nothing must be
// settled by a search that stays near it.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "fixtures.hpp"
#include "mesh/mesh.hpp"
#include "mesh/piece_tracker.hpp"
#include "mesh/traversal.hpp"
#include "mesh/validate.hpp"
#include "topology/section_cuts.hpp"
#include "topology/split_edge.hpp"

namespace snede::testing {
namespace {

struct TrackerWatcher : ConnectivityWatcher {
  PieceTracker* tracker = nullptr;
  void init(const Connectivity&) override {}
  void on_change(const Connectivity& c, const ConnectivityChange& change) override { tracker->on_change(c, change); }
};

Mesh kuhn_mesh(int n) {
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) points.insert(points.end(), {double(i), double(j), double(k)});
  std::vector<std::int64_t> cells;
  for (const auto& cell : kuhn_box(n)) cells.insert(cells.end(), cell.begin(), cell.end());
  return Mesh(3, std::move(points), cells);
}

// The tracker's labels define the same partition of the elements as the full count.
void expect_same_pieces(const Connectivity& c, const PieceTracker& tracker) {
  const auto [label, n] = connected_components(c);
  ASSERT_EQ(tracker.pieces(), n);
  std::map<int, int> full_to_tracked;
  for (ElementId e : c.element_ids()) {
    const auto [it, inserted] = full_to_tracked.emplace(label[e], tracker.label(e));
    EXPECT_EQ(it->second, tracker.label(e)) << "element " << e << " is labelled apart from its piece";
  }
  EXPECT_EQ(full_to_tracked.size(), static_cast<std::size_t>(n));
}

TEST(PieceTracker, RandomPlaneCutsAndSplitsAgreeWithAFullCount) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    Mesh mesh = kuhn_mesh(5);
    PieceTracker tracker(mesh.connectivity());
    TrackerWatcher watcher;
    watcher.tracker = &tracker;
    mesh.connectivity().add_watcher(&watcher);
    std::mt19937 random(seed);
    int separations = 0;
    for (int step = 0; step < 24; ++step) {
      const int kind = std::uniform_int_distribution<int>(0, 2)(random);
      if (kind == 0) {  // split a random edge of a random element: adds elements
        const auto ids = mesh.connectivity().element_ids();
        const Simplex s = mesh.connectivity().element(ids[std::uniform_int_distribution<std::size_t>(0, ids.size() - 1)(random)]).simplex;
        split_edge(mesh, s.vertex(0), s.vertex(1), 0.5);
      } else {  // dissect part or all of a section x, y or z = 1..4
        const int axis = std::uniform_int_distribution<int>(0, 2)(random);
        std::vector<FaceId> faces = faces_in_plane(mesh, axis, std::uniform_int_distribution<int>(1, 4)(random));
        std::shuffle(faces.begin(), faces.end(), random);
        if (kind == 1) faces.resize(faces.size() / 2);
        if (faces.empty()) continue;
        dissect_faces(mesh, faces);
      }
      const int before = tracker.pieces();
      tracker.update(mesh.connectivity());
      ASSERT_FALSE(find_violation(mesh.connectivity()));
      expect_same_pieces(mesh.connectivity(), tracker);
      separations += tracker.pieces() > before;
    }
    EXPECT_GT(separations, 0) << "seed " << seed << ": no cut separated a piece; the test exercised nothing";
    mesh.connectivity().remove_watcher(&watcher);
  }
}

TEST(PieceTracker, ANotchIsSettledNearTheCutAndASeparationIsFound) {
  const int n = 12;
  Mesh mesh = kuhn_mesh(n);
  PieceTracker tracker(mesh.connectivity());
  TrackerWatcher watcher;
  watcher.tracker = &tracker;
  mesh.connectivity().add_watcher(&watcher);
  // A notch: the faces of the section x = 6 within one cell of the corner y = z = 0.
  const auto [notch, rest] = notch_and_rest(mesh, 6);
  ASSERT_FALSE(notch.empty());
  dissect_faces(mesh, notch);
  EXPECT_FALSE(tracker.update(mesh.connectivity()));
  EXPECT_EQ(tracker.pieces(), 1);
  EXPECT_LT(tracker.last_search_size(), mesh.connectivity().n_elements() / 20)
      << "the search around a notch of " << notch.size() << " faces visited a large part of the body";
  dissect_faces(mesh, rest);
  EXPECT_TRUE(tracker.update(mesh.connectivity()));
  expect_same_pieces(mesh.connectivity(), tracker);
  EXPECT_EQ(tracker.pieces(), 2);
  mesh.connectivity().remove_watcher(&watcher);
}

}  // namespace
}  // namespace snede::testing
