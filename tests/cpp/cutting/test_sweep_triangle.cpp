// The sweep triangle's exact tests (§3.2.1): crossings of edges, including the degenerate
// contacts a snapped vertex produces, against hand-computed answers.
#include <gtest/gtest.h>

#include <array>
#include <limits>

#include "cutting/sweep_triangle.hpp"

namespace snede {
namespace {

// The triangle x = 0.5 with corners (0.5, 0, 0), (0.5, 2, 0), (0.5, 0, 2).
SweepTriangle plane_x_half() {
  const std::array<double, 9> corners{0.5, 0, 0, 0.5, 2, 0, 0.5, 0, 2};
  return SweepTriangle(corners);
}

TEST(SweepTriangle, CrossingParameterAlongTheEdge) {
  const SweepTriangle s = plane_x_half();
  const auto t = s.crossing({0, 0.5, 0.5}, {2, 0.5, 0.5});
  ASSERT_TRUE(t.has_value());
  EXPECT_DOUBLE_EQ(*t, 0.25);
  EXPECT_FALSE(s.crossing({0, 0.5, 0.5}, {0.4, 0.5, 0.5}));  // short of the plane
  EXPECT_FALSE(s.crossing({0, 1.5, 1.5}, {1, 1.5, 1.5}));    // through the plane, outside the triangle
}

TEST(SweepTriangle, AnEndOnTheTriangleTouchesAndAnEdgeInItsPlaneDoesNot) {
  const SweepTriangle s = plane_x_half();
  EXPECT_EQ(s.crossing({0.5, 0.5, 0.5}, {1, 0.5, 0.5}), std::optional<double>(0.0));
  EXPECT_EQ(s.crossing({0, 0.5, 0.5}, {0.5, 0.5, 0.5}), std::optional<double>(1.0));
  EXPECT_FALSE(s.crossing({0.5, 0.1, 0.1}, {0.5, 0.5, 0.5}));
  // Through the triangle's edge (closed triangle) counts.
  EXPECT_TRUE(s.crossing({0, 1, 0}, {1, 1, 0}));
}

TEST(SweepTriangle, MeetsTetrahedraAndTrianglesItTouches) {
  const SweepTriangle s = plane_x_half();
  const std::array<Point3, 4> across{{{0, 0.2, 0.2}, {1, 0.2, 0.2}, {0.4, 0.8, 0.2}, {0.4, 0.2, 0.8}}};
  EXPECT_TRUE(s.meets_tetrahedron(across));
  const std::array<Point3, 4> beside{{{0, 0.2, 0.2}, {0.4, 0.2, 0.2}, {0.2, 0.8, 0.2}, {0.2, 0.2, 0.8}}};
  EXPECT_FALSE(s.meets_tetrahedron(beside));
  // The triangle wholly inside a big tetrahedron.
  const std::array<Point3, 4> around{{{-10, -10, -10}, {30, -10, -10}, {-10, 30, -10}, {-10, -10, 30}}};
  EXPECT_TRUE(s.meets_tetrahedron(around));
  EXPECT_TRUE(s.meets_triangle({0, 0.5, 0.5}, {1, 0.5, 0.5}, {1, 0.6, 0.5}));
}

TEST(SweepTriangle, RefusesCollinearAndNonFiniteCorners) {
  const std::array<double, 9> collinear{0, 0, 0, 1, 1, 1, 2, 2, 2};
  EXPECT_THROW(SweepTriangle{collinear}, std::invalid_argument);
  std::array<double, 9> nan{0.5, 0, 0, 0.5, 2, 0, 0.5, 0, 2};
  nan[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(SweepTriangle{nan}, std::invalid_argument);
}

}  // namespace
}  // namespace snede
