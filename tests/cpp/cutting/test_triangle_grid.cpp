// The triangle grid's candidates for a swept scalpel: a superset of the triangles the scalpel
// actually meets during the sweep (found by brute force over every triangle at many times),
// and for a short scalpel far fewer than the whole surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "cutting/swept_intersections.hpp"
#include "cutting/triangle_grid.hpp"
#include "mesh/fixtures.hpp"

namespace snede {
namespace {

// The bell z = 0.4 exp(−r²/0.08) over the unit square, n × n squares.
Mesh bell(int n) {
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / n;
      points.insert(points.end(), {x, y, 0.4 * std::exp(-((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5)) / 0.08)});
    }
  std::vector<std::int64_t> cells;
  for (const auto& cell : testing::grid_triangles(n, n)) cells.insert(cells.end(), cell.begin(), cell.end());
  return Mesh(2, 3, std::move(points), cells);
}

Point3 point(const Mesh& mesh, VertexId v) {
  const auto x = mesh.point(v);
  return {x[0], x[1], x[2]};
}

TEST(TriangleGrid, SweepCandidatesHoldEveryTriangleTheSweepMeets) {
  const Mesh mesh = bell(14);
  TriangleGrid grid;
  grid.build(mesh, [&](VertexId v) { return point(mesh, v); });
  const Connectivity& c = mesh.connectivity();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> in_box(-0.3, 1.3), height(-0.3, 0.6), step(-0.15, 0.15);
  for (int trial = 0; trial < 200; ++trial) {
    // Long slanted scalpels (up to the whole surface) moving by up to 0.15 per end.
    const Point3 h0{in_box(random), in_box(random), height(random)}, t0{in_box(random), in_box(random), height(random)};
    const Point3 h1{h0[0] + step(random), h0[1] + step(random), h0[2] + step(random)};
    const Point3 t1{t0[0] + step(random), t0[1] + step(random), t0[2] + step(random)};
    const std::vector<ElementId> candidates = grid.near_sweep(h0, t0, h1, t1);
    for (int k = 0; k <= 50; ++k) {
      const double s = k / 50.0;
      const Point3 head = lerp(h0, h1, s), tail = lerp(t0, t1, s);
      for (ElementId e = 0; e < c.element_capacity(); ++e) {
        if (!c.is_element(e)) continue;
        const Simplex& t = c.element(e).simplex;
        const Point3 a = point(mesh, t.vertex(0));
        if (segment_meets_triangle(head, tail, a, point(mesh, t.vertex(1)), point(mesh, t.vertex(2)), a))
          ASSERT_TRUE(std::binary_search(candidates.begin(), candidates.end(), e))
              << "trial " << trial << ": triangle " << e << " met at time " << s << " is not a candidate";
      }
    }
  }
}

TEST(TriangleGrid, ShortScalpelHasFewCandidates) {
  const Mesh mesh = bell(14);  // 392 triangles, cells twice the mean edge (about 0.18)
  TriangleGrid grid;
  grid.build(mesh, [&](VertexId v) { return point(mesh, v); });
  // A vertical scalpel through (0.3, 0.3) from z = −1 to 1 moving 0.05 in x: its column of
  // cells holds a few dozen triangles at most.
  const auto candidates = grid.near_sweep({0.3, 0.3, -1}, {0.3, 0.3, 1}, {0.35, 0.3, -1}, {0.35, 0.3, 1});
  EXPECT_GT(candidates.size(), 0u);
  EXPECT_LT(candidates.size(), 60u);
  // A scalpel along the diagonal of the square at z = 0.1 is looked up piece by piece along
  // it: fewer than half the triangles, where its box holds all 392.
  const auto diagonal = grid.near_sweep({0, 0, 0.1}, {1, 1, 0.1}, {0.02, 0, 0.1}, {1.02, 1, 0.1});
  EXPECT_LT(diagonal.size(), 392u / 2);
}

}  // namespace
}  // namespace snede
