// The Delaunay cutter (§5.2.2) on a bare 2D mesh and on a body given by its displacement alone
// (no Model): a cut across the square makes two pieces (our own flood fill) of the square's
// area, every triangle positive and the mesh valid, and one that stops inside leaves one
// piece; a cut of a rigidly translated body equals the cut of the translated mesh.
#include <gtest/gtest.h>

#include <vector>

#include "cutter_checks.hpp"
#include "cutting/delaunay_cutter.hpp"

namespace snede::testing {
namespace {

PlanarCutResult cut_along(DelaunayCutter& cutter, const std::vector<PlanePoint>& corners) {
  PlanarCutResult total;
  for (const PlanePoint& p : sampled(corners, cutter.options().eps_edge)) total.add(cutter.move(p));
  return total;
}

TEST(DelaunayCutter, ACutAcrossMakesTwoPiecesOfTheSquaresArea) {
  Mesh mesh = right_triangle_square(8);
  DelaunayCutter cutter(mesh, {}, DelaunayCutterOptions{});
  PlanarCutResult report = cut_along(cutter, {{0.43, 1.2}, {0.43, 0.5}});
  EXPECT_EQ(report.entries, 1);
  EXPECT_TRUE(cutter.cutting());
  EXPECT_EQ(count_pieces(mesh), 1);
  expect_sound(mesh);
  report.add(cut_along(cutter, {{0.43, 0.5}, {0.47, -0.2}}));
  EXPECT_EQ(report.exits, 1);
  EXPECT_FALSE(cutter.cutting());
  EXPECT_EQ(count_pieces(mesh), 2);
  expect_sound(mesh);
  EXPECT_NEAR(total_measure(mesh), 1.0, 1e-12);
}

TEST(DelaunayCutter, ACutOfARigidlyTranslatedBodyIsTheCutOfTheTranslatedMesh) {
  const std::vector<double> t{0.25, -0.5};  // exact sums with the grid's coordinates
  Mesh displaced = right_triangle_square(8);
  Mesh moved = translated(displaced, t);
  DelaunayCutter on_body(displaced, rigid_displacement(displaced, t), DelaunayCutterOptions{});
  DelaunayCutter on_mesh(moved, {}, DelaunayCutterOptions{});
  std::vector<PlanePoint> path{{-0.2, 0.31}, {0.4, 0.62}, {0.7, 0.35}, {1.2, 0.58}};
  for (PlanePoint& p : path) p = {p[0] + t[0], p[1] + t[1]};
  const PlanarCutResult body_report = cut_along(on_body, path);
  const PlanarCutResult mesh_report = cut_along(on_mesh, path);
  expect_same_incision_translated(body_report, mesh_report, displaced, t, moved);
}

}  // namespace
}  // namespace snede::testing
