// Property tests: random sequences of every local edit — edge split, edge collapse, node
// snap, vertex insertion, and on triangle meshes edge flip and vertex removal — mixed with
// §7.3 dissection of a random interior face and §6.5 bisection, on a jittered square and a
// jittered Kuhn cube (with an elastic body and a model attached) and on a bumpy surface.
// After every step: the mesh is valid, the watcher's view matches it, a refused edit left it
// bit for bit unchanged, the Euler characteristic changed only by a dissection, and an affine
// displacement u = A X + b is still reproduced exactly at every vertex with an unchanged
// energy density (every edit interpolates by parents and keeps the domain).
#include <gtest/gtest.h>

#include <optional>
#include <random>

#include "topology/edit_checks.hpp"
#include "topology/random_editor.hpp"

namespace snede {
namespace {

using namespace snede::testing;

struct Tally {
  std::array<int, n_operations> done{}, refused{};
};

// V − E + F (− T): counts the distinct simplices of every dimension of the live cells.
int euler_characteristic(const Mesh& mesh) {
  std::array<std::set<std::vector<VertexId>>, 4> simplices;
  const int k = mesh.cell_dim() + 1;
  const std::vector<VertexId> cells = mesh.cells();
  for (std::size_t c = 0; c < cells.size(); c += k)
    for (int subset = 1; subset < (1 << k); ++subset) {
      std::vector<VertexId> face;
      for (int i = 0; i < k; ++i)
        if (subset & (1 << i)) face.push_back(cells[c + i]);
      std::ranges::sort(face);
      simplices[face.size() - 1].insert(face);
    }
  int chi = 0;
  for (int d = 0; d < k; ++d) chi += (d % 2 ? -1 : 1) * static_cast<int>(simplices[d].size());
  return chi;
}

class RandomEdits {
 public:
  RandomEdits(Mesh& mesh, unsigned seed, bool with_model) : mesh_(mesh), field_(mesh.dim()) {
    mesh_.connectivity().add_watcher(&watcher_);
    if (with_model) {
      physics_.emplace(mesh_);
      field_.set_on(physics_->model, mesh_);
      energy_density_ = physics_->energy_density(mesh_);
    }
    editor_.emplace(mesh_, seed);
  }
  ~RandomEdits() { mesh_.connectivity().remove_watcher(&watcher_); }
  std::size_t n_forced_splits() const { return editor_->n_forced_splits(); }

  // Counts into `tally` (a void function, so that ASSERTs can stop it).
  void run(int n_steps, Tally& tally) {
    const std::size_t start_cells = mesh_.n_cells();
    for (int step = 0; step < n_steps; ++step) {
      const Operation operation = editor_->choose(double(mesh_.n_cells()) / start_cells);
      const MeshSnapshot before(mesh_);
      const int chi = euler_characteristic(mesh_);
      const bool volume_mesh = mesh_.cell_dim() == mesh_.space_dim();
      const double boundary = volume_mesh ? boundary_measure(mesh_) : 0.0;
      const EditResult result = editor_->edit(operation);
      SCOPED_TRACE("step " + std::to_string(step) + ", " + operation_names[operation] + ": " + result.reason);
      ASSERT_NO_THROW(mesh_.validate());
      ASSERT_TRUE(watcher_.matches(mesh_.connectivity()));
      if (operation != dissection) ASSERT_EQ(euler_characteristic(mesh_), chi);
      // A bisection, forced or not, leaves no hanging vertex: no new interior "boundary".
      if (operation == bisection && volume_mesh) ASSERT_NEAR(boundary_measure(mesh_), boundary, 1e-12 * boundary);
      if (result.done) {
        ++tally.done[operation];
      } else {
        ++tally.refused[operation];
        ASSERT_FALSE(result.reason.empty());
        ASSERT_TRUE(MeshSnapshot(mesh_) == before);
      }
      if (physics_) {
        ASSERT_EQ(physics_->model.n_dofs(), mesh_.n_points() * mesh_.dim());
        ASSERT_LT(field_.deviation(physics_->model, mesh_), 1e-12);
        ASSERT_NEAR(physics_->energy_density(mesh_), energy_density_, 1e-11 * energy_density_);
      }
    }
  }

 private:
  Mesh& mesh_;
  RecordingWatcher watcher_;
  AffineField field_;
  std::optional<ModelOn> physics_;
  std::optional<RandomEditor> editor_;
  double energy_density_ = 0;
};

void expect_every_operation_exercised(const Mesh& mesh, const Tally& tally) {
  for (int op = 0; op < n_operations; ++op) {
    if (mesh.cell_dim() == 3 && (op == flip || op == removal)) continue;
    EXPECT_GT(tally.done[op], op >= dissection ? 1 : 10) << operation_names[op];
    ::testing::Test::RecordProperty(std::string("done_") + operation_names[op], tally.done[op]);
    ::testing::Test::RecordProperty(std::string("refused_") + operation_names[op], tally.refused[op]);
  }
}

// The invariant the sequences rely on, against the closed form: plane stress, uniform strain
// ε = sym(A), W = μ ε:ε + λ*/2 (tr ε)² per unit volume, times the thickness.
TEST(RandomEdits, AffineFieldHasTheAnalyticEnergyDensity) {
  Mesh mesh = jittered_square(8, 0.25, 1);
  ModelOn physics(mesh);
  const AffineField field(2);
  field.set_on(physics.model, mesh);
  const LinearElastic material(1e4, 0.3);
  const double shear = 0.5 * (field.A[1] + field.A[2]), trace = field.A[0] + field.A[3];
  const double density = material.lame.mu * (field.A[0] * field.A[0] + field.A[3] * field.A[3] + 2 * shear * shear) +
                         0.5 * material.effective_lambda<2>() * trace * trace;
  EXPECT_NEAR(physics.energy_density(mesh), density * 0.01, 1e-12 * density * 0.01);
}

TEST(RandomEdits, JitteredSquareWithAModel) {
  for (unsigned seed : {1u, 2u}) {
    Mesh mesh = jittered_square(8, 0.25, seed);
    Tally tally;
    RandomEdits(mesh, seed, true).run(500, tally);
    expect_every_operation_exercised(mesh, tally);
  }
}

TEST(RandomEdits, JitteredKuhnCubeWithAModel) {
  std::size_t n_forced = 0;
  for (unsigned seed : {3u, 4u}) {
    Mesh mesh = shuffled_jittered_cube(3, 0.2, seed);
    Tally tally;
    RandomEdits edits(mesh, seed, true);
    edits.run(500, tally);
    expect_every_operation_exercised(mesh, tally);
    n_forced += edits.n_forced_splits();
  }
  // Elements made by collapses and insertions break the labelling's compatibility; the
  // forced splits this causes were checked above like every other step.
  EXPECT_GT(n_forced, 0u);
  ::testing::Test::RecordProperty("forced_splits", static_cast<int>(n_forced));
}

TEST(RandomEdits, BumpySurface) {
  for (unsigned seed : {5u, 6u}) {
    Mesh mesh = bumpy_surface(8, 0.2, 0.3, seed);
    Tally tally;
    RandomEdits(mesh, seed, false).run(500, tally);
    expect_every_operation_exercised(mesh, tally);
  }
}

}  // namespace
}  // namespace snede
