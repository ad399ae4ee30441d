// ElasticBody::for_each_element_stiffness (fem/block_stiffness.hpp: a block's matrices from
// one FirstPiolaTangent per block, corner 0's columns as minus the others') against
// ElasticBody::element_stiffness, which applies the whole one-element tangent kernel to each
// of the (D + 1)·D unit directions. Every material, plane stress and 3D, mild and rough random
// states, and one element flattened to zero measure: the same elements are visited (inverted
// ones left out where the material forbids inversion), with the same vertices, and every
// matrix agrees to round-off.
//
// Tolerance: 1e-13 of ‖K_e‖_F times κ₂(F)² (the conditioning of the C = FᵀF the hyperelastic
// kernels invert, as in test_streamed_kernels.cpp); the two sides evaluate the same formulas
// in another order, a few ulps apart, while a wrong entry is O(‖K_e‖). Elements with
// κ₂(F)² ≥ 1e12 have no digits to compare and are only checked to be visited or left out.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <random>
#include <set>

#include "fem/elastic_body.hpp"
#include "fem/material_fixtures.hpp"
#include "topology/edit_checks.hpp"
#include "topology/refinement_checks.hpp"

namespace snede {
namespace {

using namespace snede::testing;

constexpr double tolerance = 1e-13;

// κ₂(F)² of element e at u, F from the mesh's points.
double conditioning(const Mesh& mesh, ElementId e, std::span<const double> u) {
  const int D = mesh.dim();
  const auto v = mesh.connectivity().element(e).simplex.oriented_vertices();
  Eigen::MatrixXd X(D, D), x(D, D);
  for (int j = 1; j <= D; ++j)
    for (int k = 0; k < D; ++k) {
      X(k, j - 1) = mesh.point(v[j])[k] - mesh.point(v[0])[k];
      x(k, j - 1) = X(k, j - 1) + u[v[j] * D + k] - u[v[0] * D + k];
    }
  const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(x * X.inverse()).singularValues();
  return std::pow(sigma(0) / sigma(D - 1), 2);
}

void expect_matches_element_by_element(const ElasticBody& body, std::span<const double> u, const std::string& where) {
  const Mesh& mesh = body.mesh();
  const int D = mesh.dim(), n = (D + 1) * D;
  std::set<ElementId> expected;
  for (ElementId e : mesh.cell_ids()) expected.insert(e);
  if (forbids_inversion(body.material()))
    for (ElementId e : body.inverted_elements(u)) expected.erase(e);
  std::set<ElementId> visited;
  body.for_each_element_stiffness(u, [&](ElementId e, std::span<const VertexId> vertices, std::span<const double> K) {
    EXPECT_TRUE(visited.insert(e).second) << where << ": element " << e << " visited twice";
    const auto oriented = mesh.connectivity().element(e).simplex.oriented_vertices();
    ASSERT_EQ(vertices.size(), static_cast<std::size_t>(D + 1)) << where;
    for (int j = 0; j <= D; ++j) EXPECT_EQ(vertices[j], oriented[j]) << where << ": element " << e << ", corner " << j;
    const double kappa = conditioning(mesh, e, u);
    if (!(kappa < 1e12)) return;
    const std::vector<double> reference = body.element_stiffness(e, u);
    ASSERT_EQ(K.size(), reference.size()) << where;
    const double norm = Eigen::Map<const Eigen::VectorXd>(reference.data(), n * n).norm();
    for (int i = 0; i < n * n; ++i)
      ASSERT_NEAR(K[i], reference[i], tolerance * kappa * norm)
          << where << ": element " << e << ", entry (" << i / n << ", " << i % n << "), κ₂(F)² " << kappa;
  });
  EXPECT_EQ(visited, expected) << where;
}

std::vector<double> random_field(const Mesh& mesh, double amplitude, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  std::vector<double> x(static_cast<std::size_t>(mesh.n_points()) * mesh.dim());
  for (double& xi : x) xi = amplitude * normal(rng);
  return x;
}

// u moved so that the first element's last corner lies on its first corner (zero measure,
// det F = 0: inverted for the materials that forbid it, a finite stiffness for the others).
std::vector<double> with_first_element_flattened(const Mesh& mesh, std::vector<double> u) {
  const int D = mesh.dim();
  const auto v = mesh.connectivity().element(mesh.cell_ids().front()).simplex.oriented_vertices();
  for (int k = 0; k < D; ++k) u[v[D] * D + k] = mesh.point(v[0])[k] + u[v[0] * D + k] - mesh.point(v[D])[k];
  return u;
}

TEST(BlockStiffness, MatchesElementByElement) {
  for (int dim : {2, 3})
    for (unsigned seed : {1u, 2u}) {
      Mesh mesh = dim == 2 ? jittered_square(5 + seed, 0.25, seed) : shuffled_jittered_cube(2 + seed, 0.25, seed);
      const double h = 1.0 / (dim == 2 ? 5 + seed : 2 + seed);
      std::mt19937 rng(seed);
      for (const Material& material : all_materials()) {
        const ElasticBody body(mesh, material, 1000.0, dim == 2 ? 0.01 : 0.0);
        for (double amplitude : {0.05 * h, 0.4 * h}) {
          const std::vector<double> u = random_field(mesh, amplitude, rng);
          const std::string where = std::to_string(dim) + "D, seed " + std::to_string(seed) + ", " + name_of(material) +
                                    ", |u| ~ " + std::to_string(amplitude / h) + " h";
          expect_matches_element_by_element(body, u, where);
          expect_matches_element_by_element(body, with_first_element_flattened(mesh, u), where + ", one element flat");
        }
      }
    }
}

// The rough states above invert elements (so leaving them out is checked) but not all.
TEST(BlockStiffness, RoughStatesInvertSomeElements) {
  Mesh mesh = shuffled_jittered_cube(3, 0.25, 1);
  const ElasticBody body(mesh, NeoHookean(3e3, 0.45), 1000.0, 0.0);
  std::mt19937 rng(1);
  const std::vector<double> u = random_field(mesh, 0.4 / 3, rng);
  std::size_t n_visited = 0;
  body.for_each_element_stiffness(u, [&](ElementId, std::span<const VertexId>, std::span<const double>) { ++n_visited; });
  EXPECT_GT(body.inverted_elements(u).size(), 0u);
  EXPECT_EQ(n_visited + body.inverted_elements(u).size(), mesh.n_cells());
}

}  // namespace
}  // namespace snede
