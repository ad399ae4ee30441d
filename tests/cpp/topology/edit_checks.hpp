// Meshes and checks shared by the tests of local triangle and tetrahedron edits (flip,
// insertion, removal): a snapshot that must survive every refusal bit for bit, total measure,
// jittered planar grids and a bumpy height-field surface.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "mesh/fixtures.hpp"
#include "mesh/mesh.hpp"

namespace snede::testing {

// Everything a refused edit must leave as it was.
struct MeshSnapshot {
  std::vector<VertexId> cells;
  std::vector<double> points;
  std::vector<ElementId> cell_ids;
  std::vector<VertexId> boundary_faces;
  VertexId n_points;

  explicit MeshSnapshot(const Mesh& mesh)
      : cells(mesh.cells()),
        points(mesh.points()),
        cell_ids(mesh.cell_ids()),
        boundary_faces(mesh.boundary_faces()),
        n_points(mesh.n_points()) {}
  friend bool operator==(const MeshSnapshot&, const MeshSnapshot&) = default;
};

inline Mesh mesh_from(int cell_dim, int space_dim, std::vector<double> points, const std::vector<std::vector<VertexId>>& cells) {
  std::vector<std::int64_t> flat;
  for (const auto& cell : cells) flat.insert(flat.end(), cell.begin(), cell.end());
  return Mesh(cell_dim, space_dim, std::move(points), flat);
}

// Sum of cell measures (area, volume; surface area).
inline double total_measure(const Mesh& mesh) {
  double sum = 0;
  for (ElementId e : mesh.cell_ids()) sum += mesh.measure(e);
  return sum;
}

// The unit square as n × n squares of two triangles, interior vertices moved by up to
// `jitter` cells (seeded).
inline Mesh jittered_square(int n, double jitter, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-jitter / n, jitter / n);
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const bool interior = i > 0 && i < n && j > 0 && j < n;
      points.push_back(double(i) / n + (interior ? offset(random) : 0.0));
      points.push_back(double(j) / n + (interior ? offset(random) : 0.0));
    }
  return mesh_from(2, 2, points, grid_triangles(n, n));
}

// The graph of z = h sin(2πx) sin(2πy) over the jittered unit square: an open surface.
inline Mesh bumpy_surface(int n, double height, double jitter, unsigned seed) {
  const Mesh flat = jittered_square(n, jitter, seed);
  std::vector<double> points;
  for (VertexId v = 0; v < flat.n_points(); ++v) {
    const double x = flat.point(v)[0], y = flat.point(v)[1];
    points.insert(points.end(), {x, y, height * std::sin(2 * M_PI * x) * std::sin(2 * M_PI * y)});
  }
  return mesh_from(2, 3, points, grid_triangles(n, n));
}

}  // namespace snede::testing
