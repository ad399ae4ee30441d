// Meshes and independent geometric checks shared by the bisection tests (§6.5).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "mesh/fixtures.hpp"
#include "mesh/mesh.hpp"

namespace snede::testing {

// A mesh of cell_dim-simplices in space_dim from nested cell lists (surfaces: 2, 3).
inline Mesh mesh_from(int cell_dim, int space_dim, std::vector<double> points, const std::vector<std::vector<VertexId>>& cells) {
  std::vector<std::int64_t> flat;
  for (const auto& cell : cells) flat.insert(flat.end(), cell.begin(), cell.end());
  return Mesh(cell_dim, space_dim, std::move(points), flat);
}

inline Mesh mesh_of(int dim, std::vector<double> points, const std::vector<std::vector<VertexId>>& cells) {
  return mesh_from(dim, dim, std::move(points), cells);
}

// The unit square as n × n squares of two right triangles (the mesh of Figure 6.8).
inline Mesh right_triangle_square(int n) {
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) points.insert(points.end(), {double(i) / n, double(j) / n});
  return mesh_of(2, points, grid_triangles(n, n));
}

// The cube [0, side]³ as n³ Kuhn-split cubes (Figure 6.13).
inline Mesh kuhn_cube(int n, double side = 1.0) {
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k)
        points.insert(points.end(), {double(i) / n * side, double(j) / n * side, double(k) / n * side});
  return mesh_of(3, points, kuhn_box(n));
}

// The faces of a tetrahedral mesh on the plane x = `x` whose corners all have y ≤ `y_end`,
// each once, as vertex triples one after another (what dissect takes).
inline std::vector<VertexId> faces_on_plane_x(const Mesh& mesh, double x, double y_end) {
  const std::vector<VertexId> corners = mesh.cells();
  std::set<std::array<VertexId, 3>> faces;
  for (std::size_t c = 0; c < corners.size(); c += 4)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<VertexId, 3> face{};
      int k = 0;
      bool on_plane = true;
      for (int a = 0; a < 4; ++a) {
        if (a == skip) continue;
        on_plane = on_plane && mesh.point(corners[c + a])[0] == x && mesh.point(corners[c + a])[1] <= y_end;
        face[k++] = corners[c + a];
      }
      std::sort(face.begin(), face.end());
      if (on_plane) faces.insert(face);
    }
  std::vector<VertexId> flat;
  for (const auto& face : faces) flat.insert(flat.end(), face.begin(), face.end());
  return flat;
}

// The same cube with its vertex ids shuffled and interior vertices moved by up to `jitter`
// cells: a tetrahedral mesh whose labelling by sorted ids is not Kuhn's.
inline Mesh shuffled_jittered_cube(int n, double jitter, unsigned seed) {
  const Mesh kuhn = kuhn_cube(n);
  const VertexId n_points = kuhn.n_points();
  std::vector<VertexId> new_id(n_points);
  std::iota(new_id.begin(), new_id.end(), 0);
  std::mt19937 random(seed);
  std::shuffle(new_id.begin(), new_id.end(), random);
  std::uniform_real_distribution<double> offset(-jitter / n, jitter / n);
  std::vector<double> points(kuhn.points().size());
  for (VertexId v = 0; v < n_points; ++v)
    for (int k = 0; k < 3; ++k) {
      const double x = kuhn.points()[3 * v + k];
      const bool interior = x > 0 && x < 1;
      points[3 * new_id[v] + k] = x + (interior ? offset(random) : 0.0);
    }
  std::vector<std::vector<VertexId>> cells;
  for (const auto& cell : kuhn_box(n)) cells.push_back({new_id[cell[0]], new_id[cell[1]], new_id[cell[2]], new_id[cell[3]]});
  return mesh_of(3, points, cells);
}

inline double total_volume(const Mesh& mesh) {
  double sum = 0;
  for (const ElementQuality& q : mesh.quality()) sum += q.volume;
  return sum;
}

inline double min_aspect_ratio(const Mesh& mesh) {
  double least = 1;
  for (const ElementQuality& q : mesh.quality()) least = std::min(least, q.aspect_ratio);
  return least;
}

inline std::vector<double> coordinates(const Mesh& mesh, VertexId v) {
  return {mesh.points().begin() + v * mesh.dim(), mesh.points().begin() + (v + 1) * mesh.dim()};
}

// Length (2D) or area (3D) of the boundary: a hanging vertex would add interior "boundary".
inline double boundary_measure(const Mesh& mesh) {
  const std::vector<VertexId> faces = mesh.boundary_faces();
  double sum = 0;
  for (std::size_t f = 0; f < faces.size(); f += mesh.dim()) {
    const auto a = coordinates(mesh, faces[f]), b = coordinates(mesh, faces[f + 1]);
    if (mesh.dim() == 2) {
      sum += std::hypot(b[0] - a[0], b[1] - a[1]);
    } else {
      const auto c = coordinates(mesh, faces[f + 2]);
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      sum += 0.5 * std::sqrt(std::pow(u[1] * w[2] - u[2] * w[1], 2) + std::pow(u[2] * w[0] - u[0] * w[2], 2) +
                             std::pow(u[0] * w[1] - u[1] * w[0], 2));
    }
  }
  return sum;
}

// Element edges whose midpoint is a vertex of the mesh (found by coordinates, not by the
// parents the mesh records): each one is a hanging vertex in that element.
inline std::size_t n_hanging_vertices(const Mesh& mesh) {
  std::set<std::vector<double>> vertex_positions;
  for (VertexId v = 0; v < mesh.n_points(); ++v) vertex_positions.insert(coordinates(mesh, v));
  std::size_t hanging = 0;
  for (ElementId e : mesh.cell_ids()) {
    const Simplex& s = mesh.connectivity().element(e).simplex;
    for (int i = 0; i < s.count(); ++i)
      for (int j = i + 1; j < s.count(); ++j) {
        const auto a = coordinates(mesh, s.vertex(i)), b = coordinates(mesh, s.vertex(j));
        std::vector<double> middle(a.size());
        for (std::size_t k = 0; k < a.size(); ++k) middle[k] = 0.5 * a[k] + 0.5 * b[k];
        hanging += vertex_positions.count(middle);
      }
  }
  return hanging;
}

// Classes of elements congruent up to scaling (and reflection): the sorted squared edge
// lengths divided by the largest, rounded.
using SimilarityClass = std::vector<long long>;

inline std::set<SimilarityClass> similarity_classes(const Mesh& mesh) {
  std::set<SimilarityClass> classes;
  for (ElementId e : mesh.cell_ids()) {
    const Simplex& s = mesh.connectivity().element(e).simplex;
    std::vector<double> squared;
    for (int i = 0; i < s.count(); ++i)
      for (int j = i + 1; j < s.count(); ++j) {
        const auto a = coordinates(mesh, s.vertex(i)), b = coordinates(mesh, s.vertex(j));
        double d = 0;
        for (std::size_t k = 0; k < a.size(); ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
        squared.push_back(d);
      }
    std::sort(squared.begin(), squared.end());
    SimilarityClass key;
    for (double d : squared) key.push_back(std::llround(1e8 * d / squared.back()));
    classes.insert(key);
  }
  return classes;
}

inline std::size_t n_similarity_classes(const Mesh& mesh) { return similarity_classes(mesh).size(); }

inline std::vector<double> longest_edges_at(const Mesh& mesh, const std::vector<ElementId>& elements) {
  std::vector<double> lengths;
  for (ElementId e : elements) lengths.push_back(longest_edge(mesh.dim(), mesh.corners(e)));
  return lengths;
}

}  // namespace snede::testing
