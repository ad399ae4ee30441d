// Conforming bisection (§6.5) in 2D and 3D: validity, conformity, volume, similarity classes.
#include <gtest/gtest.h>

#include "topology/bisection.hpp"
#include "topology/refinement_checks.hpp"

namespace snede {
namespace {

using namespace snede::testing;

// Checks every refinement must pass: the §7 invariants and positive volumes, no hanging
// vertex, the same volume and boundary measure as before.
void expect_conforming(const Mesh& mesh, double volume, double boundary) {
  EXPECT_NO_THROW(mesh.validate());
  EXPECT_EQ(n_hanging_vertices(mesh), 0u);
  EXPECT_NEAR(total_volume(mesh), volume, 1e-13 * volume);
  EXPECT_NEAR(boundary_measure(mesh), boundary, 1e-12 * boundary);
}

TEST(Bisection2D, UniformRefinementDoublesTheRightTrianglesAndKeepsOneShape) {
  Mesh mesh = right_triangle_square(4);
  const double start_aspect = min_aspect_ratio(mesh);
  Bisection bisection(mesh);
  for (int level = 1; level <= 8; ++level) {
    EXPECT_EQ(bisection.refine_uniform(1), 32u << (level - 1));
    EXPECT_EQ(mesh.n_cells(), 32u << level);
    expect_conforming(mesh, 1.0, 4.0);
    // Halving the hypotenuse of a right isosceles triangle gives two of them (§6.5).
    EXPECT_EQ(n_similarity_classes(mesh), 1u);
    EXPECT_NEAR(min_aspect_ratio(mesh), start_aspect, 1e-12);
  }
}

TEST(Bisection2D, BisectingALegFirstBisectsTheNeighbourHypotenuseLikeFigure67) {
  Mesh mesh = right_triangle_square(2);
  Bisection bisection(mesh);
  // Split the lower-left square along its diagonal: both triangles share that hypotenuse.
  const ElementId lower_left = bisection.hierarchy().locate(std::vector<double>{0.3, 0.1});
  EXPECT_EQ(bisection.bisect(lower_left), 2u);
  // The half at (0.45, 0.1) has as refinement edge the leg x = 0.5, which in the unrefined
  // lower-right square is a leg too; that square's diagonal is bisected first: 2 + 2 splits.
  const ElementId half = bisection.hierarchy().locate(std::vector<double>{0.45, 0.1});
  const TaggedSimplex label = bisection.hierarchy().label(half);
  const auto x = [&](VertexId v) { return mesh.points()[2 * v]; };
  EXPECT_DOUBLE_EQ(x(label.refinement_start()), 0.5);
  EXPECT_DOUBLE_EQ(x(label.refinement_end()), 0.5);
  EXPECT_EQ(bisection.bisect(half), 4u);
  EXPECT_EQ(mesh.n_cells(), 8u + 2u + 4u);
  expect_conforming(mesh, 1.0, 4.0);
}

TEST(Bisection3D, UniformRefinementOfTheKuhnCubeDoublesAndCyclesThroughThreeClasses) {
  Mesh mesh = kuhn_cube(2);
  const double start_aspect = min_aspect_ratio(mesh);
  std::vector<std::set<SimilarityClass>> classes_at_level{similarity_classes(mesh)};
  Bisection bisection(mesh);
  for (int level = 1; level <= 6; ++level) {
    EXPECT_EQ(bisection.refine_uniform(1), 48u << (level - 1));
    EXPECT_EQ(mesh.n_cells(), 48u << level);
    expect_conforming(mesh, 1.0, 6.0);
    classes_at_level.push_back(similarity_classes(mesh));
    EXPECT_GE(min_aspect_ratio(mesh), start_aspect / 2);
  }
  // One class per level (all elements of a level are congruent), a new one at levels 1 and
  // 2, and the Kuhn simplex again (halved) every 3 levels: Maubach's tags cycle (§6.5).
  std::set<SimilarityClass> all;
  for (std::size_t level = 0; level < classes_at_level.size(); ++level) {
    EXPECT_EQ(classes_at_level[level].size(), 1u);
    if (level >= 3) EXPECT_EQ(classes_at_level[level], classes_at_level[level - 3]);
    all.insert(classes_at_level[level].begin(), classes_at_level[level].end());
  }
  EXPECT_EQ(all.size(), 3u);
}

TEST(Bisection3D, ArbitraryTetrahedraRefineConformingWithBoundedClasses) {
  // Shuffled ids: the sorted-id labelling is not Kuhn's, so the mesh gets longest-edge
  // bisection and the recursion really works.
  Mesh mesh = shuffled_jittered_cube(3, 0.2, 7);
  const std::size_t n_start = mesh.n_cells();
  const double volume = total_volume(mesh), boundary = boundary_measure(mesh), start_aspect = min_aspect_ratio(mesh);
  Bisection bisection(mesh);
  for (int level = 1; level <= 4; ++level) {
    const std::size_t before = mesh.n_cells();
    const std::size_t n_split = bisection.refine_uniform(1);
    EXPECT_EQ(mesh.n_cells(), before + n_split);  // each split adds one cell
    EXPECT_GE(n_split, before);                   // every cell split at least once
    expect_conforming(mesh, volume, boundary);
  }
  EXPECT_GE(mesh.n_cells(), n_start << 4);
  // No bound on shapes is proven for 3D longest-edge bisection (Hannukainen, Korotov and
  // Křížek 2012 observe regular families); Maubach-type bisection's 36 classes per starting
  // tetrahedron (Arnold, Mukherjee and Pouly) and a sixth of the starting aspect ratio are kept
  // as checks that it stays as regular as the rule it replaced.
  EXPECT_LE(n_similarity_classes(mesh), 36 * n_start);
  EXPECT_GE(min_aspect_ratio(mesh), start_aspect / 6);
}

TEST(Bisection2D, LongestEdgeLabellingRefinesAnUnstructuredTriangulation) {
  // Jittered points with alternating diagonals: no right triangles, no common pattern.
  const int n = 6;
  std::vector<double> points;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> offset(-0.25 / n, 0.25 / n);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const bool interior_i = i > 0 && i < n, interior_j = j > 0 && j < n;
      points.insert(points.end(), {double(i) / n + (interior_i ? offset(random) : 0.0),
                                   double(j) / n + (interior_j ? offset(random) : 0.0)});
    }
  std::vector<std::vector<VertexId>> cells;
  auto v = [n](int i, int j) { return i * (n + 1) + j; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if ((i + j) % 2 == 0) {
        cells.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1)});
        cells.push_back({v(i, j), v(i + 1, j + 1), v(i, j + 1)});
      } else {
        cells.push_back({v(i, j), v(i + 1, j), v(i, j + 1)});
        cells.push_back({v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)});
      }
  Mesh mesh = mesh_of(2, points, cells);
  const std::size_t n_start = mesh.n_cells();
  const double start_aspect = min_aspect_ratio(mesh);
  Bisection bisection(mesh);
  for (int level = 1; level <= 6; ++level) {
    bisection.refine_uniform(1);
    expect_conforming(mesh, 1.0, 4.0);
  }
  EXPECT_GE(mesh.n_cells(), n_start << 6);
  // Newest-vertex bisection: at most 4 classes per starting triangle.
  EXPECT_LE(n_similarity_classes(mesh), 4 * n_start);
  EXPECT_GE(min_aspect_ratio(mesh), start_aspect / 4);
}

}  // namespace
}  // namespace snede
