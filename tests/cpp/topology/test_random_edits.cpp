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

#include "topology/bisection.hpp"
#include "topology/collapse_edge.hpp"
#include "topology/dissect.hpp"
#include "topology/edit_checks.hpp"
#include "topology/flip_edge.hpp"
#include "topology/insert_vertex.hpp"
#include "topology/remove_vertex.hpp"
#include "topology/snap_vertex.hpp"
#include "topology/split_edge.hpp"

namespace snede {
namespace {

using namespace snede::testing;

enum Operation { split, collapse, snap, insertion, flip, removal, dissection, bisection, n_operations };
constexpr const char* operation_names[] = {"split", "collapse", "snap", "insertion", "flip", "removal", "dissection", "bisection"};

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
  RandomEdits(Mesh& mesh, unsigned seed, bool with_model) : mesh_(mesh), field_(mesh.dim()), rng_(seed) {
    mesh_.connectivity().add_watcher(&watcher_);
    if (with_model) {
      physics_.emplace(mesh_);
      field_.set_on(physics_->model, mesh_);
      energy_density_ = physics_->energy_density(mesh_);
    }
    bisection_.emplace(mesh_);
  }
  ~RandomEdits() { mesh_.connectivity().remove_watcher(&watcher_); }
  std::size_t n_forced_splits() const { return bisection_->n_forced_splits(); }

  // Counts into `tally` (a void function, so that ASSERTs can stop it).
  void run(int n_steps, Tally& tally) {
    const std::size_t start_cells = mesh_.n_cells();
    for (int step = 0; step < n_steps; ++step) {
      const Operation operation = choose(double(mesh_.n_cells()) / start_cells);
      const MeshSnapshot before(mesh_);
      const int chi = euler_characteristic(mesh_);
      const bool volume_mesh = mesh_.cell_dim() == mesh_.space_dim();
      const double boundary = volume_mesh ? boundary_measure(mesh_) : 0.0;
      const EditResult result = edit(operation);
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
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

  // Keeps the size near where it started: more splits and insertions when small, more
  // collapses and removals when big. Flips and removals only on triangle meshes.
  Operation choose(double size) {
    const bool triangles = mesh_.cell_dim() == 2;
    const double u = uniform(0, 1);
    if (u < 0.02) return dissection;
    if (u < 0.05) return bisection;
    if (u < 0.05 + 0.25 / size) return integer(0, 1) ? split : insertion;
    if (u < 0.6) return triangles && integer(0, 1) ? removal : collapse;
    return triangles && integer(0, 1) ? flip : snap;
  }

  std::vector<double> random_weights(int n, double lowest) {
    std::vector<double> weights;
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += weights.emplace_back(uniform(lowest, 1));
    for (double& w : weights) w /= sum;
    return weights;
  }

  EditResult edit(Operation operation) {
    const std::vector<ElementId> ids = mesh_.cell_ids();
    const ElementId e = ids[integer(0, static_cast<int>(ids.size()) - 1)];
    const Simplex& element = mesh_.connectivity().element(e).simplex;
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
      case snap: {
        if (integer(0, 1)) return snap_vertex(mesh_, a, VertexParents::on_edge(a, b, uniform(0, 0.7)));
        const std::vector<VertexId> corners(element.vertices().begin(), element.vertices().end());
        return snap_vertex(mesh_, a, VertexParents::barycentric(corners, random_weights(element.count(), 0.05)));
      }
      case insertion: {
        std::vector<double> weights = random_weights(element.count(), 0.02);
        if (mesh_.cell_dim() == 3 && integer(0, 2) == 0) {  // on a face
          weights[i] = 0;
          double sum = 0;
          for (double w : weights) sum += w;
          for (double& w : weights) w /= sum;
        }
        return insert_vertex(mesh_, e, weights);
      }
      case flip:
        return flip_edge(mesh_, a, b);
      case removal:
        return remove_vertex_by_flips(mesh_, a);
      case dissection: {
        const Connectivity& c = mesh_.connectivity();
        const FaceId f = c.element(e).faces[i];
        if (c.face(f).mate == no_id) return EditResult::refused("boundary face drawn");
        const auto vertices = c.face(f).simplex.vertices();
        dissect(mesh_, std::vector<VertexId>(vertices.begin(), vertices.end()));
        return EditResult::success();
      }
      case bisection:
      default:
        // After other edits, new elements get a fresh labelling that may not be compatible
        // with their neighbours'; bisect then forces splits, still conforming.
        bisection_->bisect(e);
        return EditResult::success();
    }
  }

  Mesh& mesh_;
  RecordingWatcher watcher_;
  AffineField field_;
  std::optional<ModelOn> physics_;
  std::optional<Bisection> bisection_;
  double energy_density_ = 0;
  std::mt19937 rng_;
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
