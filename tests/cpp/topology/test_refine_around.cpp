// §6.5 refine-around(x, h) in 2D and 3D (Figures 6.8 and 6.13): the target size is
// reached at x, shapes stay in a few classes, and the mesh grows like log(size / h).
#include <gtest/gtest.h>

#include <cmath>

#include "topology/refine_around.hpp"
#include "topology/refinement_checks.hpp"

namespace snede {
namespace {

using namespace snede::testing;

struct Growth {
  std::vector<std::size_t> n_cells;  // after refining to h = 2^-k, k = 1, 2, ...
};

// Refines to h = 2^-k for k = 1..k_max, checking after each step that every element at x
// has edges ≤ h and that the mesh stays conforming with its volume.
Growth refine_in_steps(Mesh& mesh, Bisection& bisection, const std::vector<double>& x, int k_max) {
  Growth growth;
  const double volume = total_volume(mesh), boundary = boundary_measure(mesh);
  for (int k = 1; k <= k_max; ++k) {
    const double h = std::ldexp(1.0, -k);
    const std::size_t before = mesh.n_cells();
    const std::size_t n_split = refine_around(bisection, x, h);
    EXPECT_EQ(mesh.n_cells(), before + n_split);  // a split replaces one element by two
    const std::vector<ElementId> at_x = bisection.hierarchy().locate_all(x);
    EXPECT_FALSE(at_x.empty());
    for (double length : longest_edges_at(mesh, at_x)) EXPECT_LE(length, h);
    EXPECT_NO_THROW(mesh.validate());
    EXPECT_EQ(n_hanging_vertices(mesh), 0u);
    EXPECT_NEAR(total_volume(mesh), volume, 1e-13 * volume);
    EXPECT_NEAR(boundary_measure(mesh), boundary, 1e-12 * boundary);
    growth.n_cells.push_back(mesh.n_cells());
  }
  return growth;
}

// Elements added per halving of h, between k = 4..8 and k = 8..12: equal for logarithmic
// growth; a uniform refinement would multiply them by 2^(4·dim).
double growth_ratio(const Growth& g) {
  return double(g.n_cells[11] - g.n_cells[7]) / double(g.n_cells[7] - g.n_cells[3]);
}

TEST(RefineAround2D, TwentyLevelsOfRightTrianglesStayOneShapeAndGrowLogarithmically) {
  Mesh mesh = right_triangle_square(2);
  const double start_aspect = min_aspect_ratio(mesh);
  Bisection bisection(mesh);
  const std::vector<double> x{0.3, 0.55};
  const Growth growth = refine_in_steps(mesh, bisection, x, 20);
  // §6.5: all triangles are congruent to the starting ones (NVB's bound is 4 classes).
  EXPECT_EQ(n_similarity_classes(mesh), 1u);
  EXPECT_LE(n_similarity_classes(mesh), 4u);
  EXPECT_DOUBLE_EQ(min_aspect_ratio(mesh), start_aspect);
  EXPECT_GE(bisection.hierarchy().level(bisection.hierarchy().locate(x)), 2 * 18);
  EXPECT_NEAR(growth_ratio(growth), 1.0, 0.25);
  EXPECT_LT(mesh.n_cells(), 1000u);  // uniform refinement to 2^-20 would need 2^41 triangles
}

TEST(RefineAround3D, KuhnCubeAroundAPointStaysInThreeClassesLikeFigure613) {
  Mesh mesh = kuhn_cube(2);
  const double start_aspect = min_aspect_ratio(mesh);
  Bisection bisection(mesh);
  const std::vector<double> x{0.3, 0.55, 0.7};
  const Growth growth = refine_in_steps(mesh, bisection, x, 12);
  EXPECT_GE(bisection.hierarchy().level(bisection.hierarchy().locate(x)), 20);
  // Maubach on the Kuhn simplex: the three classes of its tags, with aspect ratios
  // 0.408 (Kuhn), 0.354 and 0.354 — the minimum is the starting one times √3/2.
  EXPECT_EQ(n_similarity_classes(mesh), 3u);
  EXPECT_NEAR(min_aspect_ratio(mesh), start_aspect * std::sqrt(3.0) / 2, 1e-9);
  EXPECT_NEAR(growth_ratio(growth), 1.0, 0.25);
  EXPECT_LT(mesh.n_cells(), 10000u);  // uniform refinement to 2^-12 would need 48·2^33
}

TEST(RefineAround3D, ArbitraryTetrahedraStayWithinMaubachsClassBound) {
  Mesh mesh = shuffled_jittered_cube(3, 0.2, 11);
  const std::size_t n_start = mesh.n_cells();
  const double start_aspect = min_aspect_ratio(mesh);
  Bisection bisection(mesh);
  const Growth growth = refine_in_steps(mesh, bisection, {0.4, 0.45, 0.6}, 12);
  EXPECT_LE(n_similarity_classes(mesh), 36 * n_start);  // Arnold–Mukherjee–Pouly's bound per starting tetrahedron
  EXPECT_GE(min_aspect_ratio(mesh), start_aspect / 6);
  EXPECT_LT(growth_ratio(growth), 2.0);
}

TEST(RefineAround3D, APointOnAVertexRefinesEveryElementAroundIt) {
  Mesh mesh = kuhn_cube(2);
  Bisection bisection(mesh);
  const std::vector<double> centre{0.5, 0.5, 0.5};  // a vertex shared by 24 tetrahedra
  refine_around(bisection, centre, 0.1);
  const std::vector<ElementId> at_centre = bisection.hierarchy().locate_all(centre);
  EXPECT_GE(at_centre.size(), 24u);
  for (ElementId e : at_centre) EXPECT_TRUE(mesh.connectivity().element(e).simplex.contains(13));  // vertex (1,1,1)
  for (double length : longest_edges_at(mesh, at_centre)) EXPECT_LE(length, 0.1);
  EXPECT_NO_THROW(mesh.validate());
}

TEST(RefineAround, RejectsBadArgumentsWithoutChangingTheMesh) {
  Mesh mesh = right_triangle_square(2);
  Bisection bisection(mesh);
  const std::vector<double> inside{0.5, 0.5};
  EXPECT_THROW(refine_around(bisection, inside, 0.0), std::invalid_argument);
  EXPECT_THROW(refine_around(bisection, inside, -1.0), std::invalid_argument);
  EXPECT_THROW(refine_around(bisection, inside, std::nan("")), std::invalid_argument);
  EXPECT_THROW(refine_around(bisection, inside, 1e-300), std::invalid_argument);
  EXPECT_THROW(refine_around(bisection, std::vector<double>{1.5, 0.5}, 0.1), std::invalid_argument);
  EXPECT_THROW(refine_around(bisection, std::vector<double>{0.5, 0.5, 0.5}, 0.1), std::invalid_argument);
  EXPECT_EQ(mesh.n_cells(), 8u);
  EXPECT_EQ(refine_around(bisection, inside, 10.0), 0u);  // already fine enough
}

}  // namespace
}  // namespace snede
