// The §6.8.1 needle situation for the needle's C++ tests (as tests/python/needle sets it up): a
// plane-stress slab 0.1 × 0.1 m, 0.01 m thick, E = 34 kPa, ν = 0.34, held at x = 0.1 m, meshed
// with right triangles of leg 0.1/32 m (no refinement at the tip); the needle enters at
// (0, 0.05) along +x, with a uniform friction profile; linear CG to rtol 1e-10.
#pragma once

#include <string>
#include <vector>

#include "core/petsc_util.hpp"
#include "mesh/fixtures.hpp"
#include "needle/needle_insertion.hpp"

namespace snede::testing {

constexpr double slab_size = 0.1, slab_edge = slab_size / 32;

inline Mesh slab_mesh() {
  const int n = 32;
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) points.insert(points.end(), {i * slab_edge, j * slab_edge});
  std::vector<std::int64_t> cells;
  for (const auto& cell : grid_triangles(n, n)) cells.insert(cells.end(), cell.begin(), cell.end());
  return Mesh(2, points, cells);
}

struct NeedleSlab {
  Mesh mesh = slab_mesh();
  ElasticBody body{mesh, LinearElastic(34e3, 0.34), 1000.0, 0.01};
  Model model{body};
  std::vector<VertexId> held;  // x = 0.1 m
  NeedleInsertion needle;

  NeedleSlab(double friction_per_length, const std::string& prefix)
      : needle(hold(model, mesh, held), nullptr, Point{0.0, 0.05, 0.0}, Point{1.0, 0.0, 0.0},
               FrictionProfile::uniform(friction_per_length), NeedleOptions{}, solver_options(prefix)) {}

  // Advances the needle by `step` until it is `depth` in, each update converged.
  void insert(double depth, double step) {
    while (needle.depth() < depth - 1e-12) {
      const NeedleStepResult report = needle.advance(step);
      ASSERT_TRUE(report.converged) << report.reason;
    }
  }
  // The sum over the held side of the forces its support exerts on the body.
  std::vector<double> support_force() {
    VecHandle reactions;
    SNEDE_PETSC(VecDuplicate(model.displacement(), reactions.out()));
    model.reaction_forces(model.displacement(), reactions);
    const std::vector<double> r = vec_values(reactions);
    std::vector<double> total(2, 0.0);
    for (VertexId v : held)
      for (int k = 0; k < 2; ++k) total[k] += r[v * 2 + k];
    return total;
  }

 private:
  static Model& hold(Model& model, const Mesh& mesh, std::vector<VertexId>& held) {
    for (VertexId v = 0; v < mesh.n_points(); ++v)
      if (mesh.point(v)[0] == slab_size) held.push_back(v);
    model.fix(held, {});
    return model;
  }
  static StaticOptions solver_options(const std::string& prefix) {
    StaticOptions options;
    options.method = StaticMethod::linear_cg;
    options.stopping.rtol = 1e-10;
    options.options_prefix = prefix;
    return options;
  }
};

}  // namespace snede::testing
