// The needle's friction profile and its queries on the deformed mesh (§6.3.2, §6.4).
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/fixtures.hpp"
#include "mesh/mesh.hpp"
#include "needle/deformed_queries.hpp"
#include "needle/friction_profile.hpp"

namespace snede {
namespace {

Mesh unit_grid(int n) {
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      points.push_back(static_cast<double>(i) / n);
      points.push_back(static_cast<double>(j) / n);
    }
  std::vector<std::int64_t> cells;
  for (const auto& cell : testing::grid_triangles(n, n)) cells.insert(cells.end(), cell.begin(), cell.end());
  return Mesh(2, points, cells);
}

TEST(FrictionProfile, IntegralMatchesAFineMidpointSum) {
  const FrictionProfile profile({0.0, 0.002, 0.005, 0.01}, {40.0, 60.0, 45.0, 20.0});
  const double a = 0.001, b = 0.03;
  const int n = 200000;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += profile.at(a + (i + 0.5) * (b - a) / n) * (b - a) / n;
  EXPECT_NEAR(profile.integral(a, b), sum, 1e-9 * sum);
  EXPECT_NEAR(profile.integral(0.02, 0.03), 20.0 * 0.01, 1e-14);  // the plateau (a difference of cumulatives)
}

TEST(FrictionProfile, RefusesNegativeForcesAndUnsortedDistances) {
  EXPECT_THROW(FrictionProfile({0.0, 1.0}, {1.0, -1.0}), std::invalid_argument);
  EXPECT_THROW(FrictionProfile({0.0, 1.0, 0.5}, {1.0, 1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(FrictionProfile({0.5}, {1.0}), std::invalid_argument);
}

TEST(DeformedQueries, ReferencePositionInvertsAnAffineDeformation) {
  const Mesh mesh = unit_grid(4);
  // u = A X + c with A = [[0.1, 0.2], [-0.05, 0.3]], c = (0.02, -0.01).
  std::vector<double> u(2 * mesh.n_points());
  for (VertexId v = 0; v < mesh.n_points(); ++v) {
    const auto X = mesh.point(v);
    u[2 * v] = 0.1 * X[0] + 0.2 * X[1] + 0.02;
    u[2 * v + 1] = -0.05 * X[0] + 0.3 * X[1] - 0.01;
  }
  const Point X{0.37, 0.61, 0.0};
  const Point x{X[0] + 0.1 * X[0] + 0.2 * X[1] + 0.02, X[1] - 0.05 * X[0] + 0.3 * X[1] - 0.01, 0.0};
  const auto found = reference_position(mesh, u, x);
  ASSERT_TRUE(found);
  EXPECT_NEAR((*found)[0], X[0], 1e-14);
  EXPECT_NEAR((*found)[1], X[1], 1e-14);
  EXPECT_FALSE(reference_position(mesh, u, Point{-1.0, 0.5, 0.0}));
}

TEST(DeformedQueries, ShaftCrossingsFindEveryEdgeAcrossTheSegmentOnce) {
  const Mesh mesh = unit_grid(4);
  const std::vector<double> u(2 * mesh.n_points(), 0.0);
  // y = 0.3 from x = −0.1 to 0.6: crosses the boundary edge x = 0, the vertical edges at
  // x = 0.25 and 0.5, and the diagonals of squares 0, 1 and 2 in row 1 (y in [0.25, 0.5]).
  const auto crossings = shaft_crossings(mesh, u, Point{-0.1, 0.3, 0.0}, Point{0.6, 0.3, 0.0});
  ASSERT_EQ(crossings.size(), 6u);
  int boundary = 0;
  for (const ShaftCrossing& c : crossings) {
    boundary += c.on_boundary;
    // Every crossed edge spans y in [0.25, 0.5]: its end closer to y = 0.3 is the needle node.
    EXPECT_EQ(mesh.point(c.near)[1], 0.25);
    EXPECT_GE(c.s, 0.0);
    EXPECT_LE(c.s, 0.7);
  }
  EXPECT_EQ(boundary, 1);
}

}  // namespace
}  // namespace snede
