// Random sequences of flips, insertions and removals on a jittered 2D grid (with an elastic
// model attached) and on a bumpy surface. Every edit either succeeds and leaves a valid mesh,
// or is refused and leaves it bit for bit unchanged. On the 2D mesh an affine displacement
// field survives every edit exactly: these edits keep the domain, and a vertex added with
// barycentric parents gets the affine value of its position, so the energy of the uniform
// strain stays W(A) · area · thickness.
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <set>

#include "core/error.hpp"
#include "solve/model.hpp"
#include "topology/edit_checks.hpp"
#include "topology/flip_edge.hpp"
#include "topology/insert_vertex.hpp"
#include "topology/remove_vertex.hpp"

namespace snede {
namespace {

using namespace snede::testing;

enum EditKind { flip, insertion, removal };

// Applies a random edit of a random kind to a random place of the mesh.
class RandomEdits {
 public:
  RandomEdits(Mesh& mesh, unsigned seed) : mesh_(mesh), random_(seed) {}

  std::pair<EditKind, EditResult> next() {
    const std::vector<ElementId> cells = mesh_.cell_ids();
    const ElementId e = cells[std::uniform_int_distribution<std::size_t>(0, cells.size() - 1)(random_)];
    const auto corners = mesh_.connectivity().element(e).simplex.oriented_vertices();
    const int j = std::uniform_int_distribution<int>(0, 2)(random_);
    const double kind = std::uniform_real_distribution<double>(0, 1)(random_);
    if (kind < 0.4) return {flip, flip_edge(mesh_, corners[j], corners[(j + 1) % 3])};
    if (kind < 0.7) return {removal, remove_vertex_by_flips(mesh_, corners[j])};
    std::uniform_real_distribution<double> weight(0.02, 1);
    std::array<double, 3> weights{weight(random_), weight(random_), weight(random_)};
    const double sum = weights[0] + weights[1] + weights[2];
    for (double& w : weights) w /= sum;
    return {insertion, insert_vertex(mesh_, e, weights)};
  }

 private:
  Mesh& mesh_;
  std::mt19937 random_;
};

// Runs n_edits random edits; after each, checks refusals left the mesh unchanged and runs
// `after_success` on successes. Returns the number of successes per kind.
std::array<int, 3> run_random_edits(Mesh& mesh, int n_edits, unsigned seed, const std::function<void()>& after_success) {
  RecordingWatcher watcher;
  mesh.connectivity().add_watcher(&watcher);
  RandomEdits edits(mesh, seed);
  std::array<int, 3> n_done{0, 0, 0};
  for (int step = 0; step < n_edits; ++step) {
    const MeshSnapshot before(mesh);
    const auto [kind, result] = edits.next();
    if (!result.done) {
      EXPECT_FALSE(result.reason.empty());
      EXPECT_TRUE(MeshSnapshot(mesh) == before) << "step " << step << ": " << result.reason;
      continue;
    }
    ++n_done[kind];
    EXPECT_NO_THROW(mesh.validate()) << "step " << step;
    EXPECT_TRUE(watcher.matches(mesh.connectivity())) << "step " << step;
    after_success();
    if (::testing::Test::HasFailure()) break;
  }
  mesh.connectivity().remove_watcher(&watcher);
  return n_done;
}

// V − E + F over the live cells.
int euler_characteristic(const Mesh& mesh) {
  const std::vector<VertexId> cells = mesh.cells();
  std::set<std::pair<VertexId, VertexId>> edges;
  for (std::size_t i = 0; i < cells.size(); i += 3)
    for (int j = 0; j < 3; ++j) edges.insert(std::minmax(cells[i + j], cells[i + (j + 1) % 3]));
  return static_cast<int>(mesh.n_live_points()) - static_cast<int>(edges.size()) + static_cast<int>(mesh.n_cells());
}

std::vector<double> values_of(Vec v) {
  const PetscScalar* data = nullptr;
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  SNEDE_PETSC(VecGetArrayRead(v, &data));
  std::vector<double> values(data, data + n);
  SNEDE_PETSC(VecRestoreArrayRead(v, &data));
  return values;
}

TEST(RandomTriangleEdits, JitteredGridKeepsAnAffineFieldAndItsEnergyExactly) {
  Mesh mesh = jittered_square(8, 0.3, 11);
  constexpr double thickness = 0.1;
  const LinearElastic material(1e3, 0.3);
  ElasticBody body(mesh, material, 1.0, thickness);
  Model model(body);
  // u(X) = A X + b: a uniform strain ε = sym(A).
  const double A[2][2] = {{0.01, -0.004}, {0.007, -0.003}}, b[2] = {0.2, -0.1};
  const auto affine = [&](VertexId v, int k) { return A[k][0] * mesh.point(v)[0] + A[k][1] * mesh.point(v)[1] + b[k]; };
  {
    PetscScalar* u = nullptr;
    SNEDE_PETSC(VecGetArray(model.displacement(), &u));
    for (VertexId v = 0; v < mesh.n_points(); ++v)
      for (int k = 0; k < 2; ++k) u[2 * v + k] = affine(v, k);
    SNEDE_PETSC(VecRestoreArray(model.displacement(), &u));
  }
  const double shear = 0.5 * (A[0][1] + A[1][0]), trace = A[0][0] + A[1][1];
  const double strain_energy_density =
      material.lame.mu * (A[0][0] * A[0][0] + A[1][1] * A[1][1] + 2 * shear * shear) +
      0.5 * material.effective_lambda<2>() * trace * trace;
  const double area = total_measure(mesh);
  EXPECT_NEAR(area, 1.0, 1e-14);
  EvaluationReport report;
  const double energy = body.energy(values_of(model.displacement()), report);
  EXPECT_NEAR(energy, strain_energy_density * area * thickness, 1e-12 * energy);

  const std::array<int, 3> n_done = run_random_edits(mesh, 400, 5, [&] {
    ASSERT_EQ(model.n_dofs(), mesh.n_points() * mesh.dim());
    const std::vector<double> u = values_of(model.displacement());
    for (VertexId v = 0; v < mesh.n_points(); ++v) {
      if (!mesh.is_vertex(v)) continue;
      for (int k = 0; k < 2; ++k) ASSERT_NEAR(u[2 * v + k], affine(v, k), 1e-12 * std::abs(affine(v, k))) << "vertex " << v;
    }
    EXPECT_NEAR(total_measure(mesh), area, 1e-13);
    EvaluationReport after;
    EXPECT_NEAR(body.energy(u, after), energy, 1e-11 * energy);
    EXPECT_EQ(euler_characteristic(mesh), 1);
  });
  for (int kind : {flip, insertion, removal}) EXPECT_GE(n_done[kind], 10) << "edit kind " << kind;
}

TEST(RandomTriangleEdits, BumpySurfaceStaysAValidDisc) {
  Mesh mesh = bumpy_surface(8, 0.15, 0.3, 23);
  ASSERT_EQ(euler_characteristic(mesh), 1);  // a disc
  const std::array<int, 3> n_done = run_random_edits(mesh, 400, 9, [&] {
    // Flips, insertions and removals keep the topology: still a disc, no pinched vertex.
    EXPECT_EQ(euler_characteristic(mesh), 1);
  });
  for (int kind : {flip, insertion, removal}) EXPECT_GE(n_done[kind], 10) << "edit kind " << kind;
}

}  // namespace
}  // namespace snede
