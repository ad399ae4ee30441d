// The surface cutter (§5.3) on a bare surface and on a body given by its displacement alone
// (no Model): a cut across a flat square makes two pieces (our own flood fill) of the square's
// area, every triangle non-flat and the mesh valid; a cut of a rigidly translated bell equals
// the cut of the translated bell.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "cutter_checks.hpp"
#include "cutting/surface_cutter.hpp"

namespace snede::testing {
namespace {

// The unit square at height z = height(x, y), n × n squares of two triangles.
template <typename Height>
Mesh height_field(int n, Height height) {
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / n;
      points.insert(points.end(), {x, y, height(x, y)});
    }
  return mesh_from(2, 3, std::move(points), grid_triangles(n, n));
}

// Vertical scalpels from z = −1 to 1 through the path's samples, all moved by t.
PlanarCutResult cut_along(SurfaceCutter& cutter, const std::vector<PlanePoint>& corners,
                          const std::vector<double>& t = {0, 0, 0}) {
  PlanarCutResult total;
  for (const PlanePoint& p : sampled(corners, cutter.options().eps_edge)) {
    const std::array<double, 6> scalpel{p[0] + t[0], p[1] + t[1], -1 + t[2], p[0] + t[0], p[1] + t[1], 1 + t[2]};
    total.add(cutter.move(scalpel));
  }
  return total;
}

TEST(SurfaceCutter, ACutAcrossAFlatSquareMakesTwoPiecesOfItsArea) {
  Mesh mesh = height_field(8, [](double, double) { return 0.0; });
  SurfaceCutter cutter(mesh, {}, SurfaceCutterOptions{});
  const PlanarCutResult report = cut_along(cutter, {{0.43, 1.2}, {0.43, 0.5}, {0.47, -0.2}});
  EXPECT_EQ(report.entries, 1);
  EXPECT_EQ(report.exits, 1);
  EXPECT_EQ(count_pieces(mesh), 2);
  expect_sound(mesh);
  EXPECT_NEAR(total_measure(mesh), 1.0, 1e-12);
}

TEST(SurfaceCutter, ACutThatStopsInsideLeavesOnePiece) {
  Mesh mesh = height_field(8, [](double, double) { return 0.0; });
  SurfaceCutter cutter(mesh, {}, SurfaceCutterOptions{});
  const PlanarCutResult report = cut_along(cutter, {{0.43, 1.2}, {0.43, 0.5}});
  EXPECT_EQ(report.entries, 1);
  EXPECT_GT(cutter.incision_edges().size(), 0u);
  EXPECT_EQ(count_pieces(mesh), 1);
  expect_sound(mesh);
}

TEST(SurfaceCutter, ACutOfARigidlyTranslatedBodyIsTheCutOfTheTranslatedMesh) {
  const std::vector<double> t{0.25, -0.5, 1.0};
  Mesh displaced = height_field(8, [](double x, double y) {
    return 0.4 * std::exp(-((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5)) / 0.08);
  });
  Mesh moved = translated(displaced, t);
  SurfaceCutter on_body(displaced, rigid_displacement(displaced, t), SurfaceCutterOptions{});
  SurfaceCutter on_mesh(moved, {}, SurfaceCutterOptions{});
  const std::vector<PlanePoint> path{{-0.2, 0.31}, {0.4, 0.62}, {0.7, 0.35}, {1.2, 0.58}};
  const PlanarCutResult body_report = cut_along(on_body, path, t);
  const PlanarCutResult mesh_report = cut_along(on_mesh, path, t);
  expect_same_incision_translated(body_report, mesh_report, displaced, t, moved);
}

}  // namespace
}  // namespace snede::testing
