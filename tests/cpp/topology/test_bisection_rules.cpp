// The two 3D bisection rules (initial_labelling.hpp): Maubach's on the Kuhn box, longest-edge
// on any other mesh; refinements along random segments stay conforming under both, and each
// keeps what its labelling promises.
#include <gtest/gtest.h>

#include <random>
#include <tuple>

#include "topology/bisection.hpp"
#include "topology/refine_near_segment.hpp"
#include "topology/refinement_checks.hpp"

namespace snede {
namespace {

using namespace snede::testing;

double squared_length(const Mesh& mesh, VertexId a, VertexId b) {
  double sum = 0;
  for (int k = 0; k < 3; ++k) sum += (mesh.point(a)[k] - mesh.point(b)[k]) * (mesh.point(a)[k] - mesh.point(b)[k]);
  return sum;
}

// Random segments through the unit cube, refined to random sizes within random radii, then a
// few random single bisections: what a needle's steps and a user's clicks do to the mesh.
void refine_randomly(Bisection& bisection, unsigned seed, int n_segments) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0), size(0.04, 0.2), reach(0.0, 0.1);
  for (int s = 0; s < n_segments; ++s) {
    const std::array<double, 3> a{unit(random), unit(random), unit(random)}, b{unit(random), unit(random), unit(random)};
    refine_near_segment(bisection, a, b, size(random), reach(random));
    const std::vector<ElementId> live = bisection.mesh().connectivity().element_ids();
    for (int k = 0; k < 5; ++k) bisection.bisect(live[random() % live.size()]);
  }
}

// The largest difference of levels between face neighbours.
int largest_level_jump(const Bisection& bisection) {
  const Connectivity& c = bisection.mesh().connectivity();
  int jump = 0;
  for (ElementId e : c.element_ids())
    for (int j = 0; j < 4; ++j)
      if (const ElementId n = c.neighbor(e, j); n != no_id)
        jump = std::max(jump, std::abs(bisection.hierarchy().level(e) - bisection.hierarchy().level(n)));
  return jump;
}

TEST(BisectionRules, TheKuhnBoxKeepsMaubachAndAnyOtherMeshBisectsLongestEdges) {
  Mesh kuhn = kuhn_cube(2);
  EXPECT_EQ(Bisection(kuhn).hierarchy().rule(), BisectionRule::newest_vertex);
  Mesh jittered = shuffled_jittered_cube(3, 0.2, 7);
  EXPECT_EQ(Bisection(jittered).hierarchy().rule(), BisectionRule::longest_edge);
  // The same Kuhn cells with shuffled ids: the sorted labelling no longer bisects the diagonals.
  Mesh shuffled = shuffled_jittered_cube(3, 0.0, 7);
  EXPECT_EQ(Bisection(shuffled).hierarchy().rule(), BisectionRule::longest_edge);
}

TEST(BisectionRules, LongestEdgeRefinementStaysConformingAndEveryCellBisectsItsLongestEdge) {
  for (unsigned seed : {1u, 2u, 3u}) {
    Mesh mesh = shuffled_jittered_cube(3, 0.2, seed);
    const double volume = total_volume(mesh), boundary = boundary_measure(mesh);
    Bisection bisection(mesh);
    refine_randomly(bisection, seed, 6);
    EXPECT_NO_THROW(mesh.validate());
    EXPECT_EQ(n_hanging_vertices(mesh), 0u);
    EXPECT_NEAR(total_volume(mesh), volume, 1e-13 * volume);
    EXPECT_NEAR(boundary_measure(mesh), boundary, 1e-12 * boundary);
    // The recursion follows strictly longer edges: it never has to force a split.
    EXPECT_EQ(bisection.n_forced_splits(), 0u) << "seed " << seed;
    EXPECT_GT(mesh.n_cells(), 10 * 6 * 27u);
    for (ElementId e : mesh.connectivity().element_ids()) {
      const TaggedSimplex& label = bisection.hierarchy().label(e);
      const double refined = squared_length(mesh, label.refinement_start(), label.refinement_end());
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          ASSERT_GE(refined, squared_length(mesh, label.vertex[i], label.vertex[j])) << "element " << e;
    }
  }
}

TEST(BisectionRules, MaubachRefinementOfTheKuhnBoxKeepsFaceNeighboursWithinOneLevel) {
  // The compatible labelling of the Kuhn box: a refinement's closure splits exactly what keeps
  // neighbours' levels within one (a jump of two would be a wave the labelling does not need).
  for (unsigned seed : {1u, 2u, 3u}) {
    Mesh mesh = kuhn_cube(3);
    Bisection bisection(mesh);
    refine_randomly(bisection, seed, 6);
    EXPECT_NO_THROW(mesh.validate());
    EXPECT_EQ(n_hanging_vertices(mesh), 0u);
    EXPECT_EQ(bisection.n_forced_splits(), 0u);
    EXPECT_LE(largest_level_jump(bisection), 1) << "seed " << seed;
    EXPECT_GT(mesh.n_cells(), 10 * 6 * 27u);
  }
}

}  // namespace
}  // namespace snede
