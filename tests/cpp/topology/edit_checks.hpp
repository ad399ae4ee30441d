// Meshes and independent checks shared by the tests of local triangle and tetrahedron edits
// (flip, insertion, removal, split, collapse, snap): a bit-for-bit snapshot for refused edits,
// total measure, jittered and curved meshes, and an affine displacement field that every edit
// must carry over exactly (parents interpolate it).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "core/petsc_util.hpp"
#include "fem/linear_elastic.hpp"
#include "mesh/fixtures.hpp"
#include "mesh/mesh.hpp"
#include "problem/model.hpp"
#include "topology/local_star.hpp"
#include "topology/refinement_checks.hpp"

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
    points.insert(points.end(), {x, y, height * std::sin(2 * std::numbers::pi * x) * std::sin(2 * std::numbers::pi * y)});
  }
  return mesh_from(2, 3, points, grid_triangles(n, n));
}

// The vertices joined to v by an edge, ascending.
inline std::vector<VertexId> neighbours(const Mesh& mesh, VertexId v) {
  std::set<VertexId> found;
  for (ElementId e : local_star(mesh.connectivity(), v).elements)
    for (VertexId w : mesh.connectivity().element(e).simplex.vertices())
      if (w != v) found.insert(w);
  return {found.begin(), found.end()};
}

inline bool on_boundary(const Mesh& mesh, VertexId v) {
  for (const auto& entry : mesh.connectivity().boundary())
    if (entry.first.contains(v)) return true;
  return false;
}

// u = A X + b on the model's state; edits interpolate displacements with the same parents as
// positions, so it must stay affine in the (moved) reference positions.
struct AffineField {
  int dim;
  std::vector<double> A, b;  // (dim, dim) row-major, (dim)

  explicit AffineField(int d) : dim(d) {
    for (int i = 0; i < d; ++i) {
      b.push_back(0.01 * (i + 1));
      for (int j = 0; j < d; ++j) A.push_back(i == j ? 0.02 : 0.003 * (i + 2 * j + 1));
    }
  }
  std::vector<double> at(std::span<const double> x) const {
    std::vector<double> u(b);
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j) u[i] += A[i * dim + j] * x[j];
    return u;
  }
  void set_on(Model& model, const Mesh& mesh) const {
    std::vector<double> u(model.n_dofs(), 0.0);
    for (VertexId v = 0; v < mesh.n_points(); ++v)
      if (mesh.is_vertex(v)) std::ranges::copy(at(mesh.point(v)), u.begin() + v * dim);
    set_vec_values(model.displacement(), u);
  }
  // The largest relative deviation from A X + b at a live vertex.
  double deviation(const Model& model, const Mesh& mesh) const {
    const std::vector<double> u = vec_values(model.displacement());
    double worst = 0;
    for (VertexId v = 0; v < mesh.n_points(); ++v) {
      if (!mesh.is_vertex(v)) continue;
      const std::vector<double> expected = at(mesh.point(v));
      for (int k = 0; k < dim; ++k)
        worst = std::max(worst, std::abs(u[v * dim + k] - expected[k]) / (std::abs(expected[k]) + 1e-2));
    }
    return worst;
  }
};

// A linear elastic body with a model on `mesh` (plane stress in 2D).
struct ModelOn {
  ElasticBody body;
  Model model;
  explicit ModelOn(Mesh& mesh) : body(mesh, LinearElastic(1e4, 0.3), 1000.0, mesh.dim() == 2 ? 0.01 : 0.0), model(body) {}
  double energy_density(const Mesh& mesh) {
    EvaluationReport report;
    return body.energy(vec_values(model.displacement()), report) / total_measure(mesh);
  }
};

}  // namespace snede::testing
