// The weights that carry a needle's move into the tissue (move_extension.hpp): a discrete
// harmonic extension, checked against its defining equations once the sweeps have converged,
// bounded by the maximum principle, and zero where the vertices may not move.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "needle/move_extension.hpp"
#include "topology/refinement_checks.hpp"

namespace snede {
namespace {

using namespace snede::testing;

// Vertex neighbours through shared cells, and boundary vertices, computed from the cell list.
struct Graph {
  std::map<VertexId, std::set<VertexId>> neighbours;
  std::set<VertexId> boundary;
};

Graph graph_of(const Mesh& mesh) {
  Graph g;
  const std::vector<VertexId> cells = mesh.cells();
  std::map<std::set<VertexId>, int> faces;
  for (std::size_t c = 0; c < cells.size(); c += 4) {
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (a != b) g.neighbours[cells[c + a]].insert(cells[c + b]);
    for (int skip = 0; skip < 4; ++skip) {
      std::set<VertexId> face;
      for (int a = 0; a < 4; ++a)
        if (a != skip) face.insert(cells[c + a]);
      ++faces[face];
    }
  }
  for (const auto& [face, count] : faces)
    if (count == 1) g.boundary.insert(face.begin(), face.end());
  return g;
}

TEST(MoveExtension, ConvergedWeightsAreHarmonicBoundedAndZeroWhereVerticesMayNotMove) {
  Mesh mesh = kuhn_cube(6);
  const Graph g = graph_of(mesh);
  // A "shaft" of moved vertices through the middle of the cube along x, at y = z = 0.5.
  std::vector<VertexId> moved;
  VertexId fixed_vertex = no_id;
  for (VertexId v = 0; v < mesh.n_points(); ++v) {
    const auto x = mesh.point(v);
    if (x[1] == 0.5 && x[2] == 0.5 && x[0] > 0 && x[0] < 1) moved.push_back(v);
    if (x[0] == 0.5 && x[1] == 0.5 && std::abs(x[2] - 4.0 / 6) < 1e-12) fixed_vertex = v;
  }
  ASSERT_EQ(moved.size(), 5u);
  ASSERT_NE(fixed_vertex, no_id);
  Constraints constraints(3);
  constraints.resize(mesh.n_points());
  constraints.fix(std::span<const VertexId>(&fixed_vertex, 1), {});
  const int rings = 2;
  const auto weights = move_extension_weights(mesh, constraints, moved, rings, 2000);
  std::map<VertexId, double> w(weights.begin(), weights.end());
  ASSERT_FALSE(w.empty());
  const std::set<VertexId> held(moved.begin(), moved.end());
  auto weight_of = [&](VertexId v) { return held.count(v) ? 1.0 : w.count(v) ? w.at(v) : 0.0; };
  for (const auto& [v, value] : w) {
    EXPECT_EQ(held.count(v), 0u);
    EXPECT_EQ(g.boundary.count(v), 0u) << "a boundary vertex moved";
    EXPECT_NE(v, fixed_vertex);
    EXPECT_GT(value, 0.0);
    EXPECT_LT(value, 1.0);  // maximum principle: strictly between the held values
    // Harmonic: the mean of the neighbours' weights (the sweeps converge geometrically on a
    // graph of a few hundred vertices; 2000 sweeps leave round-off).
    double sum = 0;
    for (VertexId n : g.neighbours.at(v)) sum += weight_of(n);
    EXPECT_NEAR(value, sum / g.neighbours.at(v).size(), 1e-12) << "vertex " << v;
  }
  // Within `rings` edges of the shaft only: no edge of the Kuhn cells is longer than a cell's
  // diagonal, √3 / 6.
  for (const auto& [v, value] : w) {
    const auto x = mesh.point(v);
    EXPECT_LE(std::hypot(x[1] - 0.5, x[2] - 0.5), rings * std::sqrt(3.0) / 6 + 1e-12);
  }
}

TEST(MoveExtension, NoRingsNoWeightsAndNegativeCountsAreRefused) {
  Mesh mesh = kuhn_cube(2);
  Constraints constraints(3);
  constraints.resize(mesh.n_points());
  const std::vector<VertexId> moved{13};  // the centre of the 2 × 2 × 2 box
  EXPECT_TRUE(move_extension_weights(mesh, constraints, moved, 0, 5).empty());
  // The centre's ring is the whole boundary: nothing inside the body may move.
  EXPECT_TRUE(move_extension_weights(mesh, constraints, moved, 1, 5).empty());
  EXPECT_THROW(move_extension_weights(mesh, constraints, moved, -1, 5), std::invalid_argument);
  EXPECT_THROW(move_extension_weights(mesh, constraints, moved, 1, -1), std::invalid_argument);
}

}  // namespace
}  // namespace snede
