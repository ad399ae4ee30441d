// Property tests: thousands of random sequences of replace_elements / change_elements /
// dissect on 2D and 3D meshes, with validate() and the watcher's view checked after each step.
#include <gtest/gtest.h>

#include <random>

#include "fixtures.hpp"
#include "topology/dissect.hpp"
#include "mesh/traversal.hpp"
#include "mesh/validate.hpp"

using namespace snede;
using snede::testing::RecordingWatcher;

namespace {

class RandomEditor {
 public:
  RandomEditor(Connectivity& c, VertexId next_vertex, unsigned seed) : c_(c), next_(next_vertex), rng_(seed) {}

  ElementId random_element() {
    const auto ids = c_.element_ids();
    return ids[std::uniform_int_distribution<std::size_t>(0, ids.size() - 1)(rng_)];
  }
  int random_int(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

  // Bisect a random edge of a random element: every element around the edge is split in two
  // at a new vertex (replace_elements; always a valid change).
  void bisect_edge() {
    const ElementId e = random_element();
    const Simplex& tau = c_.element(e).simplex;
    int i = random_int(0, c_.dim()), j = random_int(0, c_.dim() - 1);
    if (j >= i) ++j;
    const VertexId p = tau.vertex(i), q = tau.vertex(j), m = next_++;
    const std::vector<ElementId> around = elements_around(c_, Simplex(1, {p, q}), e);
    std::vector<Simplex> children;
    for (ElementId old : around) {
      children.push_back(c_.element(old).simplex.substituted(p, m));
      children.push_back(c_.element(old).simplex.substituted(q, m));
    }
    c_.replace_elements(around, children);
  }
  // Split an element at a new interior vertex (1 -> d+1 elements).
  void star_split() {
    const ElementId e = random_element();
    const Simplex tau = c_.element(e).simplex;
    const VertexId m = next_++;
    std::vector<Simplex> children;
    for (int j = 0; j <= c_.dim(); ++j) children.push_back(tau.substituted(tau.vertex(j), m));
    const std::vector<ElementId> old{e};
    c_.replace_elements(old, children);
  }
  // Remove an element and put the same simplex back (its faces pair up again).
  void remove_and_restore() {
    const ElementId e = random_element();
    const std::vector<Simplex> same{c_.element(e).simplex};
    const std::vector<ElementId> old{e};
    c_.replace_elements(old, {});
    c_.replace_elements({}, same);
  }
  // Remove a random element for good (keeps at least a few).
  void remove() {
    if (c_.n_elements() < 4) return;
    const std::vector<ElementId> old{random_element()};
    c_.replace_elements(old, {});
  }
  // change_elements: give a random subset of a vertex's star a fresh copy of the vertex.
  void detach_part_of_star() {
    const ElementId e = random_element();
    const VertexId v = c_.element(e).simplex.vertex(random_int(0, c_.dim()));
    const auto star = vertex_star(c_, v, e);
    const VertexId w = next_++;
    std::vector<ElementSubstitution> substitution;
    for (ElementId t : star)
      if (random_int(0, 1)) substitution.push_back({t, {{v, w}}});
    c_.change_elements(substitution);
  }
  // dissect along a few random interior faces.
  void dissect_random_faces() {
    std::vector<FaceId> cut;
    for (int k = random_int(1, 4); k > 0; --k) {
      const ElementId e = random_element();
      const FaceId f = c_.element(e).faces[random_int(0, c_.dim())];
      if (c_.face(f).mate != no_id) cut.push_back(f);
    }
    if (cut.empty()) return;
    dissect(c_, cut, [this](VertexId) { return next_++; });
  }

  void random_step() {
    switch (random_int(0, 5)) {
      case 0: bisect_edge(); break;
      case 1: star_split(); break;
      case 2: remove_and_restore(); break;
      case 3: remove(); break;
      case 4: detach_part_of_star(); break;
      default: dissect_random_faces(); break;
    }
  }

 private:
  Connectivity& c_;
  VertexId next_;
  std::mt19937 rng_;
};

void run_sequences(int dim, int n_sequences, int n_steps) {
  int n_changes = 0;
  std::size_t largest = 0;
  for (int sequence = 0; sequence < n_sequences; ++sequence) {
    const auto cells = dim == 2 ? snede::testing::grid_triangles(3, 3) : snede::testing::kuhn_box(2);
    Connectivity c = snede::testing::connectivity_of(dim, cells);
    RecordingWatcher watcher;
    c.add_watcher(&watcher);
    RandomEditor editor(c, snede::testing::max_vertex(cells) + 1, 1000u * dim + sequence);
    for (int step = 0; step < n_steps; ++step) {
      editor.random_step();
      const auto violation = find_violation(c);
      ASSERT_FALSE(violation) << "dim " << dim << " sequence " << sequence << " step " << step << ": " << *violation;
      ASSERT_TRUE(watcher.matches(c)) << "dim " << dim << " sequence " << sequence << " step " << step;
    }
    n_changes += watcher.n_changes;
    largest = std::max(largest, c.n_elements());
  }
  // The sequences really changed the meshes (a skipped step makes no change).
  EXPECT_GT(n_changes, n_sequences * n_steps * 3 / 4);
  EXPECT_GT(largest, dim == 2 ? 30u : 60u);
}

}  // namespace

TEST(RandomChanges, Triangles) { run_sequences(2, 1000, 15); }
TEST(RandomChanges, Tetrahedra) { run_sequences(3, 1000, 15); }
