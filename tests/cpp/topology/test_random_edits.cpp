// Property tests: hundreds of random edge splits, edge collapses and node snaps on a jittered
// square, a jittered Kuhn cube (with an elastic body and a model attached) and a bumpy
// surface. After every step: the mesh is valid, the watcher's view matches it, a refused edit
// left it bit for bit unchanged, and an affine displacement u = A X + b is still reproduced
// exactly at every vertex with an unchanged energy density (edits interpolate by parents).
#include <gtest/gtest.h>

#include <optional>
#include <random>

#include "topology/collapse_edge.hpp"
#include "topology/edit_checks.hpp"
#include "topology/snap_vertex.hpp"
#include "topology/split_edge.hpp"

namespace snede {
namespace {

using namespace snede::testing;

enum Operation { split, collapse, snap };

struct Tally {
  std::array<int, 3> done{}, refused{};
};

class RandomEdits {
 public:
  RandomEdits(Mesh& mesh, unsigned seed, bool with_model) : mesh_(mesh), field_(mesh.dim()), rng_(seed) {
    mesh_.connectivity().add_watcher(&watcher_);
    if (with_model) {
      physics_.emplace(mesh_);
      field_.set_on(physics_->model, mesh_);
      energy_density_ = physics_->energy_density(mesh_);
    }
  }
  ~RandomEdits() { mesh_.connectivity().remove_watcher(&watcher_); }

  // Counts into `tally` (a void function, so that ASSERTs can stop it).
  void run(int n_steps, Tally& tally) {
    const std::size_t start_cells = mesh_.n_cells();
    for (int step = 0; step < n_steps; ++step) {
      // Keep the size near where it started: split more when small, collapse more when big.
      const double size = double(mesh_.n_cells()) / start_cells;
      const double u = uniform(0, 1);
      const Operation operation = u < 0.4 / size ? split : u < 0.75 ? collapse : snap;
      const MeshSnapshot before(mesh_);
      const EditResult result = edit(operation);
      SCOPED_TRACE("step " + std::to_string(step) + ", operation " + std::to_string(operation) + ": " + result.reason);
      ASSERT_NO_THROW(mesh_.validate());
      ASSERT_TRUE(watcher_.matches(mesh_.connectivity()));
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
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

  EditResult edit(Operation operation) {
    const std::vector<ElementId> ids = mesh_.cell_ids();
    const Simplex& element = mesh_.connectivity().element(ids[integer(0, static_cast<int>(ids.size()) - 1)]).simplex;
    const int i = integer(0, element.count() - 1);
    const int j = (i + integer(1, element.count() - 1)) % element.count();
    const VertexId a = element.vertex(i), b = element.vertex(j);
    switch (operation) {
      case split:
        return split_edge(mesh_, a, b, uniform(0.05, 0.95));
      case collapse: {
        const double choice = uniform(0, 1);
        return collapse_edge(mesh_, a, b, choice < 0.4 ? 0.0 : choice < 0.7 ? 0.5 : uniform(0, 1));
      }
      case snap:
      default:
        if (integer(0, 1)) return snap_vertex(mesh_, a, VertexParents::on_edge(a, b, uniform(0, 0.7)));
        // Somewhere inside the element: positive barycentric weights.
        std::vector<double> weights;
        double sum = 0;
        for (int k = 0; k < element.count(); ++k) sum += weights.emplace_back(uniform(0.05, 1));
        for (double& w : weights) w /= sum;
        const std::vector<VertexId> corners(element.vertices().begin(), element.vertices().end());
        return snap_vertex(mesh_, a, VertexParents::barycentric(corners, weights));
    }
  }

  Mesh& mesh_;
  RecordingWatcher watcher_;
  AffineField field_;
  std::optional<ModelOn> physics_;
  double energy_density_ = 0;
  std::mt19937 rng_;
};

void expect_every_operation_exercised(const Tally& tally) {
  for (int op = 0; op < 3; ++op) {
    EXPECT_GT(tally.done[op], 10) << "operation " << op;
    ::testing::Test::RecordProperty("done_" + std::to_string(op), tally.done[op]);
    ::testing::Test::RecordProperty("refused_" + std::to_string(op), tally.refused[op]);
  }
}

TEST(RandomEdits, JitteredSquareWithAModel) {
  for (unsigned seed : {1u, 2u}) {
    Mesh mesh = jittered_square(8, 0.25, seed);
    Tally tally;
    RandomEdits(mesh, seed, true).run(300, tally);
    expect_every_operation_exercised(tally);
  }
}

TEST(RandomEdits, JitteredKuhnCubeWithAModel) {
  for (unsigned seed : {3u, 4u}) {
    Mesh mesh = shuffled_jittered_cube(3, 0.2, seed);
    Tally tally;
    RandomEdits(mesh, seed, true).run(300, tally);
    expect_every_operation_exercised(tally);
  }
}

TEST(RandomEdits, BumpySurface) {
  for (unsigned seed : {5u, 6u}) {
    Mesh mesh = bumpy_surface(8, 0.2, 0.0, 1);
    Tally tally;
    RandomEdits(mesh, seed, false).run(300, tally);
    expect_every_operation_exercised(tally);
  }
}

}  // namespace
}  // namespace snede
