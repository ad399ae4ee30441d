// One random local edit at a time, the mix the property tests drive meshes with: edge split,
// edge collapse, node snap, vertex insertion, and on triangle meshes edge flip and vertex
// removal, mixed with §7.3 dissection of a random interior face and §6.5 bisection.
#pragma once

#include <random>
#include <vector>

#include "mesh/mesh.hpp"
#include "topology/bisection.hpp"
#include "topology/collapse_edge.hpp"
#include "topology/dissect.hpp"
#include "topology/edit_result.hpp"
#include "topology/flip_edge.hpp"
#include "topology/insert_vertex.hpp"
#include "topology/remove_vertex.hpp"
#include "topology/snap_vertex.hpp"
#include "topology/split_edge.hpp"

namespace snede::testing {

enum Operation { split, collapse, snap, insertion, flip, removal, dissection, bisection, n_operations };
constexpr const char* operation_names[] = {"split", "collapse", "snap", "insertion", "flip", "removal", "dissection", "bisection"};

class RandomEditor {
 public:
  // Labels the mesh for bisection (watching it from now on); `seed` fixes the sequence.
  RandomEditor(Mesh& mesh, unsigned seed) : mesh_(mesh), bisection_(mesh), rng_(seed) {}
  RandomEditor(const RandomEditor&) = delete;
  RandomEditor& operator=(const RandomEditor&) = delete;

  std::size_t n_forced_splits() const { return bisection_.n_forced_splits(); }
  Bisection& bisector() { return bisection_; }

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

  // Applies `operation` at a random element of the mesh; a refused edit leaves it unchanged.
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
        bisection_.bisect(e);
        return EditResult::success();
    }
  }

 private:
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

  std::vector<double> random_weights(int n, double lowest) {
    std::vector<double> weights;
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += weights.emplace_back(uniform(lowest, 1));
    for (double& w : weights) w /= sum;
    return weights;
  }

  Mesh& mesh_;
  Bisection bisection_;
  std::mt19937 rng_;
};

}  // namespace snede::testing
