// The surface cutter's intersections (§5.3): a scalpel piercing a triangle, a swept scalpel
// crossing an edge (equation (5.1), Figure 5.15) and the distance between lines, against
// answers worked out by hand for configurations chosen so that they can be.
#include <gtest/gtest.h>

#include <cmath>

#include "cutting/swept_intersections.hpp"

namespace snede {
namespace {

// The right triangle in the plane z = 0 with corners a = (0, 0, 0), b = (1, 0, 0), c = (0, 1, 0):
// the barycentric weights of (x, y, 0) are (1 − x − y, x, y).
const Point3 A{0, 0, 0}, B{1, 0, 0}, C{0, 1, 0};

void expect_weights(const TriangleHit& hit, double wa, double wb, double wc) {
  EXPECT_NEAR(hit.weights[0], wa, 1e-14);
  EXPECT_NEAR(hit.weights[1], wb, 1e-14);
  EXPECT_NEAR(hit.weights[2], wc, 1e-14);
}

TEST(SegmentMeetsTriangle, ThroughTheInterior) {
  // Vertical through (0.25, 0.25): halfway along, weights (0.5, 0.25, 0.25).
  auto hit = segment_meets_triangle({0.25, 0.25, -1}, {0.25, 0.25, 1}, A, B, C, A);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->along, 0.5, 1e-15);
  expect_weights(*hit, 0.5, 0.25, 0.25);
  // Slanted from (0, 0.25, −1) to (0.5, 0.25, 3): z = 0 a quarter along, at x = 0.125.
  hit = segment_meets_triangle({0, 0.25, -1}, {0.5, 0.25, 3}, A, B, C, A);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->along, 0.25, 1e-15);
  expect_weights(*hit, 0.625, 0.125, 0.25);
  // The triangle x + y + z = 1 and the diagonal from the origin to (1, 1, 1): the centroid,
  // a third along.
  hit = segment_meets_triangle({0, 0, 0}, {1, 1, 1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, A);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->along, 1.0 / 3, 1e-15);
  expect_weights(*hit, 1.0 / 3, 1.0 / 3, 1.0 / 3);
}

TEST(SegmentMeetsTriangle, ThroughAVertexOrAnEdgeTheOtherWeightsAreExactlyZero) {
  auto hit = segment_meets_triangle({1, 0, -1}, {1, 0, 1}, A, B, C, A);  // through b
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->weights[0], 0.0);
  EXPECT_DOUBLE_EQ(hit->weights[1], 1.0);
  EXPECT_EQ(hit->weights[2], 0.0);
  hit = segment_meets_triangle({0.5, 0, -1}, {0.5, 0, 1}, A, B, C, A);  // through the middle of ab
  ASSERT_TRUE(hit);
  expect_weights(*hit, 0.5, 0.5, 0);
  EXPECT_EQ(hit->weights[2], 0.0);
  hit = segment_meets_triangle({0.5, 0.5, -2}, {0.5, 0.5, 2}, A, B, C, A);  // through the middle of bc
  ASSERT_TRUE(hit);
  expect_weights(*hit, 0, 0.5, 0.5);
  EXPECT_EQ(hit->weights[0], 0.0);
  // The triangle x + y + z = 1, whose edge from (1, 0, 0) to (0, 1, 0) the segment from the
  // origin to (1, 1, 0) crosses at its middle, halfway along: the weight of (0, 0, 1) is 0.
  hit = segment_meets_triangle({0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, A);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->along, 0.5, 1e-15);
  expect_weights(*hit, 0.5, 0.5, 0);
  EXPECT_EQ(hit->weights[2], 0.0);
}

TEST(SegmentMeetsTriangle, MissesAndEndsOnThePlane) {
  EXPECT_FALSE(segment_meets_triangle({0.6, 0.6, -1}, {0.6, 0.6, 1}, A, B, C, A));      // beyond bc
  EXPECT_FALSE(segment_meets_triangle({-0.1, 0.5, -1}, {-0.1, 0.5, 1}, A, B, C, A));    // beside ca
  EXPECT_FALSE(segment_meets_triangle({0.25, 0.25, 0.5}, {0.25, 0.25, 1}, A, B, C, A)); // short of the plane
  // An end on the triangle: met at that end.
  const auto hit = segment_meets_triangle({0.25, 0.25, 0}, {0.25, 0.25, 1}, A, B, C, A);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->along, 0.0);
  expect_weights(*hit, 0.5, 0.25, 0.25);
  // A degenerate (collinear) triangle meets nothing.
  EXPECT_FALSE(segment_meets_triangle({0.5, 0, -1}, {0.5, 0, 1}, A, B, {2, 0, 0}, A));
}

TEST(SegmentMeetsTriangle, FlatInThePlaneTheNearestPointOfThePiece) {
  // The line y = 0.25 from x = −1 to 2 lies in the triangle for x in [0, 0.75], i.e. along
  // in [1/3, 7/12] (x = 3 along − 1).
  const Point3 p{-1, 0.25, 0}, q{2, 0.25, 0};
  auto hit = segment_meets_triangle(p, q, A, B, C, {0.1, 0.25, 5});  // nearest: x = 0.1
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->along, 1.1 / 3, 1e-15);
  expect_weights(*hit, 0.65, 0.1, 0.25);
  hit = segment_meets_triangle(p, q, A, B, C, {1.5, 0.25, 0});  // beyond the piece: its end on bc
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->along, 7.0 / 12, 1e-15);
  expect_weights(*hit, 0, 0.75, 0.25);
  hit = segment_meets_triangle(p, q, A, B, C, {-5, 0, 0});  // before the piece: its end on ca
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->along, 1.0 / 3, 1e-15);
  expect_weights(*hit, 0.75, 0, 0.25);
  EXPECT_FALSE(segment_meets_triangle({-1, 1.5, 0}, {2, 1.5, 0}, A, B, C, A));  // in the plane, outside
  EXPECT_FALSE(segment_meets_triangle({-1, 0.25, 0}, {-0.5, 0.25, 0}, A, B, C, A));  // on its line, short of it
}

void expect_crossing(const std::optional<SweptCrossing>& crossing, double time, double along, double on_edge,
                     double tolerance = 1e-12) {
  ASSERT_TRUE(crossing);
  EXPECT_NEAR(crossing->time, time, tolerance);
  EXPECT_NEAR(crossing->along, along, tolerance);
  EXPECT_NEAR(crossing->on_edge, on_edge, tolerance);
}

TEST(SweptSegmentMeetsEdge, AVerticalScalpelTranslatedAcrossAnEdge) {
  // The scalpel from z = −1 (head) to z = 3 (tail) at y = 0.5 moves from x = −1 to x = 3; the
  // edge runs along the y axis from y = −1 to 3. They meet at x = 0 (a quarter of the way),
  // at z = 0 (a quarter along the scalpel) and y = 0.5 (0.375 along the edge).
  const auto crossing =
      swept_segment_meets_edge({-1, 0.5, -1}, {-1, 0.5, 3}, {3, 0.5, -1}, {3, 0.5, 3}, {0, -1, 0}, {0, 3, 0});
  expect_crossing(crossing, 0.25, 0.25, 0.375);
  // The same sweep beside the edge (y = 3.5) or above it (z from 0.5) crosses nothing.
  EXPECT_FALSE(
      swept_segment_meets_edge({-1, 3.5, -1}, {-1, 3.5, 3}, {3, 3.5, -1}, {3, 3.5, 3}, {0, -1, 0}, {0, 3, 0}));
  EXPECT_FALSE(
      swept_segment_meets_edge({-1, 0.5, 0.5}, {-1, 0.5, 3}, {3, 0.5, 0.5}, {3, 0.5, 3}, {0, -1, 0}, {0, 3, 0}));
  // Stopping short of the edge, or moving parallel to it (f(γ) constant, not zero): none.
  EXPECT_FALSE(
      swept_segment_meets_edge({-1, 0.5, -1}, {-1, 0.5, 3}, {-0.1, 0.5, -1}, {-0.1, 0.5, 3}, {0, -1, 0}, {0, 3, 0}));
  EXPECT_FALSE(
      swept_segment_meets_edge({-1, 0.5, -1}, {-1, 0.5, 3}, {-1, 2.5, -1}, {-1, 2.5, 3}, {0, -1, 0}, {0, 3, 0}));
}

// In the next two sweeps both ends stay in the plane y = 0 and the edge runs along the y axis
// from (0, −1, 0) to (0, 1, 0), so the lines are coplanar exactly when the scalpel's line passes
// through the origin: h_z t_x − h_x t_z = 0 (h, t the ends), and then they meet at the middle
// of the edge. With the head moving from (−1, 0, −1) to (1, 0, −1), h_x = 2γ − 1, h_z = −1.

TEST(SweptSegmentMeetsEdge, OfTwoCrossingsTheFirst) {
  // Tail from (1.75, 0, 1) to (−2.25, 0, 3): t_x = 1.75 − 4γ, t_z = 1 + 2γ; the condition is
  // 4γ² − 4γ + 0.75 = 0, γ = 0.25 or 0.75, and both are crossings. At γ = 0.25 the scalpel
  // runs from (−0.5, 0, −1) to (0.75, 0, 1.5) and passes the origin 1/2.5 along.
  const auto crossing =
      swept_segment_meets_edge({-1, 0, -1}, {1.75, 0, 1}, {1, 0, -1}, {-2.25, 0, 3}, {0, -1, 0}, {0, 1, 0});
  expect_crossing(crossing, 0.25, 0.4, 0.5);
}

TEST(SweptSegmentMeetsEdge, ARootWhereTheLinesMeetBeyondTheScalpelIsNoCrossing) {
  // Tail from (−0.25, 0, −1) to (−0.25, 0, 1): t_z = 2γ − 1; the condition is again
  // 4γ² − 4γ + 0.75 = 0. At γ = 0.25 the origin is on the scalpel's line twice its length
  // beyond the head (a miss); at γ = 0.75 the scalpel runs from (0.5, 0, −1) to (−0.25, 0, 0.5)
  // and passes the origin 2/3 along.
  const auto crossing =
      swept_segment_meets_edge({-1, 0, -1}, {-0.25, 0, -1}, {1, 0, -1}, {-0.25, 0, 1}, {0, -1, 0}, {0, 1, 0});
  expect_crossing(crossing, 0.75, 2.0 / 3, 0.5);
}

TEST(SweptSegmentMeetsEdge, TouchingAtTheStartIsACrossingAtTimeZero) {
  // The scalpel starts on the edge's end a (its middle at (0, −1, 0)) and moves away.
  const auto crossing =
      swept_segment_meets_edge({0, -1, -1}, {0, -1, 1}, {2, -1, -1}, {2, -1, 1}, {0, -1, 0}, {0, 1, 0});
  expect_crossing(crossing, 0, 0.5, 0);
}

TEST(SweptSegmentMeetsEdge, FlatOnThePlaneOfTheEdgeTheFirstContactIsSampled) {
  // Everything in z = 0: the scalpel lies along y = 0.5 from x = 4γ − 3 (head) to 4γ − 2
  // (tail), the edge on the y axis from y = −1 to 1. The tail touches it at γ = 0.5, 0.75 along
  // the edge. The sweep's contact is found to within the documented 1e-9 of the lengths
  // (here 4), and the bisection stops at most that far before the touch: γ ≥ 0.5 − 1e-9.
  const auto crossing =
      swept_segment_meets_edge({-3, 0.5, 0}, {-2, 0.5, 0}, {1, 0.5, 0}, {2, 0.5, 0}, {0, -1, 0}, {0, 1, 0});
  expect_crossing(crossing, 0.5, 1, 0.75, 2e-9);
  // Sliding along y = 1.5, beyond the edge's end: no contact.
  EXPECT_FALSE(
      swept_segment_meets_edge({-3, 1.5, 0}, {-2, 1.5, 0}, {1, 1.5, 0}, {2, 1.5, 0}, {0, -1, 0}, {0, 1, 0}));
}

TEST(SweptSegmentMeetsEdge, ShortFlatContactIsFound) {
  // Everything in z = 0: the scalpel along y from −1 to 1 at x = 2.1γ − 1, the edge from
  // (0, −0.5, 0) to (0.01, 0.5, 0), nearly parallel to it. The scalpel first touches the edge at
  // its end a when x = 0: γ = 1/2.1 (0.476), a quarter along the scalpel, and leaves it at
  // x = 0.01, γ = 0.481: a contact shorter than 1/64 of the sweep.
  const auto crossing =
      swept_segment_meets_edge({-1, -1, 0}, {-1, 1, 0}, {1.1, -1, 0}, {1.1, 1, 0}, {0, -0.5, 0}, {0.01, 0.5, 0});
  ASSERT_TRUE(crossing);
  expect_crossing(crossing, 1 / 2.1, 0.25, 0);
}

TEST(LineDistance, SkewIntersectingAndParallelLines) {
  // The x axis and the line parallel to y through (0, 0, 2): 2.
  EXPECT_NEAR(line_distance({0, 0, 0}, {1, 0, 0}, {0, 0, 2}, {0, 1, 2}), 2.0, 1e-15);
  // The diagonals y = x in z = 0 and y = 1 − x in z = 3: 3, though the segments' nearest
  // points (here the lines' nearest points lie outside the second segment) are farther apart.
  EXPECT_NEAR(line_distance({0, 0, 0}, {1, 1, 0}, {2, -1, 3}, {3, -2, 3}), 3.0, 1e-14);
  // Lines that cross: 0.
  EXPECT_NEAR(line_distance({-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}), 0.0, 1e-15);
  // Parallel lines 5 apart (3 in y, 4 in z): the segments overlap in x, so 5; shifted apart
  // along x, the documented distance is the segments' nearest points', from (1, 0, 0) to
  // (3, 3, 4): √29.
  EXPECT_NEAR(line_distance({0, 0, 0}, {1, 0, 0}, {0, 3, 4}, {2, 3, 4}), 5.0, 1e-15);
  EXPECT_NEAR(line_distance({0, 0, 0}, {1, 0, 0}, {3, 3, 4}, {5, 3, 4}), std::sqrt(29.0), 1e-14);
}

}  // namespace
}  // namespace snede
