// Checks shared by the cutters' tests, independent of the cutters: pieces by a flood fill of
// our own over shared faces, measures from the corners' coordinates, the connectivity's own
// validation, and a rigid displacement against the translated mesh.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "cutting/cut_body.hpp"
#include "cutting/delaunay_cutter.hpp"
#include "mesh/mesh.hpp"
#include "mesh/validate.hpp"
#include "topology/refinement_checks.hpp"

namespace snede::testing {

using PlanePoint = std::array<double, 2>;

// The polyline `corners` sampled at most `step` apart, its corners kept (the scalpel's
// positions along a path, as snede.planar_cutting.sample_path makes them).
inline std::vector<PlanePoint> sampled(const std::vector<PlanePoint>& corners, double step) {
  std::vector<PlanePoint> points{corners.front()};
  for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
    const PlanePoint a = corners[i], b = corners[i + 1];
    const int pieces = std::max(1, static_cast<int>(std::ceil(std::hypot(b[0] - a[0], b[1] - a[1]) / step)));
    for (int k = 1; k <= pieces; ++k)
      points.push_back({a[0] + (b[0] - a[0]) * k / pieces, a[1] + (b[1] - a[1]) * k / pieces});
  }
  return points;
}

// Rows of mesh.cells(), one per live cell.
inline std::vector<std::vector<VertexId>> cell_rows(const Mesh& mesh) {
  const std::vector<VertexId> flat = mesh.cells();
  const std::size_t corners = static_cast<std::size_t>(mesh.cell_dim()) + 1;
  std::vector<std::vector<VertexId>> rows;
  for (std::size_t i = 0; i < flat.size(); i += corners) rows.emplace_back(flat.begin() + i, flat.begin() + i + corners);
  return rows;
}

// The piece of each row of cell_rows(mesh): cells joined through a shared face (cell_dim
// common vertices) are in one piece. Pieces are numbered 0, 1, … in the order first met.
inline std::vector<int> piece_of_each_cell(const Mesh& mesh) {
  const std::vector<std::vector<VertexId>> rows = cell_rows(mesh);
  std::map<std::vector<VertexId>, std::vector<std::size_t>> cells_on_face;
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t skip = 0; skip < rows[r].size(); ++skip) {
      std::vector<VertexId> face;
      for (std::size_t k = 0; k < rows[r].size(); ++k)
        if (k != skip) face.push_back(rows[r][k]);
      std::sort(face.begin(), face.end());
      cells_on_face[face].push_back(r);
    }
  std::vector<std::vector<std::size_t>> neighbours(rows.size());
  for (const auto& [face, cells] : cells_on_face)
    for (std::size_t a : cells)
      for (std::size_t b : cells)
        if (a != b) neighbours[a].push_back(b);
  std::vector<int> piece(rows.size(), -1);
  int pieces = 0;
  for (std::size_t seed = 0; seed < rows.size(); ++seed) {
    if (piece[seed] >= 0) continue;
    std::vector<std::size_t> stack{seed};
    piece[seed] = pieces;
    while (!stack.empty()) {
      const std::size_t r = stack.back();
      stack.pop_back();
      for (std::size_t n : neighbours[r])
        if (piece[n] < 0) piece[n] = pieces, stack.push_back(n);
    }
    ++pieces;
  }
  return piece;
}

inline int count_pieces(const Mesh& mesh) {
  const std::vector<int> piece = piece_of_each_cell(mesh);
  return piece.empty() ? 0 : *std::max_element(piece.begin(), piece.end()) + 1;
}

// Volume of a tetrahedron, area of a triangle: signed in 3D and in the plane (positive for a
// positively oriented cell), the area on a surface (positive unless flat).
inline double cell_measure(const Mesh& mesh, const std::vector<VertexId>& cell) {
  const auto at = [&](int k) {
    const auto p = mesh.point(cell[k]);
    return std::array<double, 3>{p[0], p[1], mesh.space_dim() == 3 ? p[2] : 0.0};
  };
  const auto a = at(0);
  const auto edge = [&](int k) {
    const auto p = at(k);
    return std::array<double, 3>{p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  };
  const auto e1 = edge(1), e2 = edge(2);
  const std::array<double, 3> n{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  if (mesh.cell_dim() == 3) {
    const auto e3 = edge(3);
    return (n[0] * e3[0] + n[1] * e3[1] + n[2] * e3[2]) / 6;
  }
  if (mesh.space_dim() == 2) return n[2] / 2;
  return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 2;
}

inline double total_measure(const Mesh& mesh) {
  double total = 0;
  for (const auto& cell : cell_rows(mesh)) total += cell_measure(mesh, cell);
  return total;
}

// Valid connectivity (7.1)–(7.5), and no inverted or flat cell.
inline void expect_sound(const Mesh& mesh) {
  const auto violation = find_violation(mesh.connectivity());
  EXPECT_FALSE(violation) << violation.value_or("");
  for (const auto& cell : cell_rows(mesh)) EXPECT_GT(cell_measure(mesh, cell), 0);
}

// The same points moved by t (mesh.dim() components), the same cells.
inline Mesh translated(const Mesh& mesh, const std::vector<double>& t) {
  std::vector<double> points = mesh.points();
  for (std::size_t i = 0; i < points.size(); ++i) points[i] += t[i % t.size()];
  return mesh_from(mesh.cell_dim(), mesh.space_dim(), std::move(points), cell_rows(mesh));
}

// u = t at every point row the mesh has when it is read (rows added by a cut included).
inline DisplacementSource rigid_displacement(const Mesh& mesh, const std::vector<double>& t) {
  return [&mesh, t] {
    auto u = std::make_shared<std::vector<double>>();
    for (VertexId v = 0; v < mesh.n_points(); ++v) u->insert(u->end(), t.begin(), t.end());
    return DisplacementRead{*u, u};
  };
}

// A cut of `displaced` under the rigid displacement t equals the cut of `moved`, its
// translated copy, cut as it is: the same cells, and the same points once moved by t.
inline void expect_same_cut_translated(const Mesh& displaced, const std::vector<double>& t, const Mesh& moved,
                                       double tolerance) {
  ASSERT_EQ(displaced.cells(), moved.cells());
  ASSERT_EQ(displaced.n_points(), moved.n_points());
  for (VertexId v = 0; v < displaced.n_points(); ++v) {
    if (!displaced.is_vertex(v)) continue;
    for (int k = 0; k < displaced.dim(); ++k)
      EXPECT_NEAR(displaced.point(v)[k] + t[k], moved.point(v)[k], tolerance) << "vertex " << v << " coordinate " << k;
  }
}

// The same for the Delaunay cutters, whose path across the body exits once and separates it
// in two: the reports count the same edits.
inline void expect_same_incision_translated(const PlanarCutResult& on_body, const PlanarCutResult& on_mesh,
                                            const Mesh& displaced, const std::vector<double>& t, const Mesh& moved) {
  EXPECT_EQ(on_body.exits, 1);
  EXPECT_EQ(on_body.flips, on_mesh.flips);
  EXPECT_EQ(on_body.incision_splits, on_mesh.incision_splits);
  EXPECT_EQ(count_pieces(displaced), 2);
  expect_sound(displaced);
  expect_same_cut_translated(displaced, t, moved, 1e-12);
}

}  // namespace snede::testing
