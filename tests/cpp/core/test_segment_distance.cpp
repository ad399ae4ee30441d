// Segment–simplex distances against a brute-force minimum over dense samples of both sets: the
// samples' minimum is never below the exact distance, and exceeds it by at most the samples'
// spacing.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/segment_distance.hpp"

namespace snede {
namespace {

// Points of the closed simplex on a barycentric lattice of n steps per edge.
std::vector<Point3> simplex_samples(const std::vector<Point3>& corners, int n) {
  std::vector<Point3> samples;
  const int d = static_cast<int>(corners.size()) - 1;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j)
      for (int k = 0; i + j + k <= n; ++k) {
        if (d == 2 && k > 0) break;
        const double w[4] = {double(i) / n, double(j) / n, d == 3 ? double(k) / n : 0.0,
                             1.0 - double(i + j + (d == 3 ? k : 0)) / n};
        Point3 x{};
        for (int c = 0; c <= d; ++c) x = plus_scaled(x, c < d ? w[c] : w[3], corners[c]);
        samples.push_back(x);
      }
  return samples;
}

double sampled_distance(const Point3& a, const Point3& b, const std::vector<Point3>& corners, int n) {
  const std::vector<Point3> on_simplex = simplex_samples(corners, n);
  double nearest = 1e300;
  for (int s = 0; s <= 4 * n; ++s) {
    const Point3 x = lerp(a, b, double(s) / (4 * n));
    for (const Point3& y : on_simplex) nearest = std::min(nearest, distance(x, y));
  }
  return nearest;
}

// Largest edge of the simplex and length of the segment: the samples are at most
// diameter / n apart on the simplex and length / (4n) on the segment.
double spacing(const Point3& a, const Point3& b, const std::vector<Point3>& corners, int n) {
  double diameter = 0;
  for (const Point3& p : corners)
    for (const Point3& q : corners) diameter = std::max(diameter, distance(p, q));
  return diameter / n + distance(a, b) / (4 * n);
}

TEST(SegmentDistance, MatchesDenseSamplingForRandomTetrahedraAndTriangles) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  auto point = [&] { return Point3{coordinate(random), coordinate(random), coordinate(random)}; };
  const int n = 24;
  for (int trial = 0; trial < 60; ++trial) {
    const int corners_count = trial % 3 == 0 ? 3 : 4;
    std::vector<Point3> corners;
    for (int c = 0; c < corners_count; ++c) corners.push_back(point());
    // Segments of every kind: short ones near the simplex, long ones through it, points.
    const Point3 a = point(), b = trial % 7 == 0 ? a : plus_scaled(a, trial % 2 ? 0.3 : 2.0, minus(point(), a));
    const double exact = segment_simplex_distance(a, b, corners);
    const double sampled = sampled_distance(a, b, corners, n);
    EXPECT_LE(exact, sampled + 1e-12) << "trial " << trial;
    EXPECT_GE(exact, sampled - spacing(a, b, corners, n)) << "trial " << trial;
  }
}

TEST(SegmentDistance, ExactCasesInsidePiercingParallelAndInThePlane) {
  // Crossings are found as closest points, which meet up to the rounding of unit coordinates.
  const std::vector<Point3> tet{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_EQ(segment_simplex_distance({0.1, 0.1, 0.1}, {0.2, 0.1, 0.1}, tet), 0.0);  // inside
  EXPECT_LE(segment_simplex_distance({0.2, 0.2, -1}, {0.2, 0.2, 2}, tet), 1e-15);   // through two faces
  // Parallel to the face z = 0 at height −0.5, above its interior: 0.5 exactly.
  EXPECT_DOUBLE_EQ(segment_simplex_distance({0.1, 0.1, -0.5}, {0.3, 0.2, -0.5}, tet), 0.5);
  // Beyond the corner (1, 0, 0) along x.
  EXPECT_DOUBLE_EQ(segment_simplex_distance({2, 0, 0}, {3, 0, 0}, tet), 1.0);
  // 2D: a triangle and a segment in the plane z = 0, crossing it without an endpoint inside.
  const std::vector<Point3> triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_LE(segment_simplex_distance({-1, 0.2, 0}, {2, 0.2, 0}, triangle), 1e-15);
  EXPECT_DOUBLE_EQ(segment_simplex_distance({-1, 2, 0}, {-1, 3, 0}, triangle), std::sqrt(2.0));
  EXPECT_THROW(segment_simplex_distance({0, 0, 0}, {1, 0, 0}, std::vector<Point3>(2)), std::invalid_argument);
}

}  // namespace
}  // namespace snede
