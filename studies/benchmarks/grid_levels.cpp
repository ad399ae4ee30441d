// Benchmark (not a test): building GridMultigrid's levels (its constructor, what the cut loop's
// SnedeGridLevels event times after every edit) on a cut block.
//
//     build/cpp/grid_levels [levels ...]   (default: 0 2; a 16³ Kuhn box of 24 576 tetrahedra,
//                                           uniformly bisected `levels` times)
//
// The block is a 0.1 m cube with its bottom face fixed and a cut dissected along half of its
// mid-plane x = 0.05, as the interactive cut loop leaves it. For each block prints ms per
// construction (best of several) and the share of the mesh passes the constructor starts with
// that can be timed alone (mean edge length, vertex stars).
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "best_seconds.hpp"
#include "bisection_levels_argument.hpp"
#include "core/petsc_session.hpp"
#include "fem/elastic_body.hpp"
#include "mesh/traversal.hpp"
#include "multigrid/coarse_basis.hpp"
#include "multigrid/grid_multigrid.hpp"
#include "problem/model.hpp"
#include "topology/bisection.hpp"
#include "topology/dissect.hpp"
#include "topology/refinement_checks.hpp"

namespace {

using namespace snede;
using benchmarks::best_seconds;

constexpr double side = 0.1;

Mesh cut_block(int levels) {
  Mesh mesh = testing::kuhn_cube(16, side);
  if (levels > 0) Bisection(mesh).refine_uniform(levels);
  // Half the mid-plane: the faces on x = side/2 with y below side/2.
  dissect(mesh, testing::faces_on_plane_x(mesh, side / 2, side / 2));
  return mesh;
}

void run_block(int levels) {
  Mesh mesh = cut_block(levels);
  ElasticBody body(mesh, LinearElastic(3e3, 0.3), 1000.0, 0.0);
  Model model(body);
  std::vector<VertexId> bottom;
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v) && mesh.point(v)[2] == 0) bottom.push_back(v);
  model.fix(bottom, {});
  const int repeats = mesh.n_cells() > 50000 ? 20 : 50;
  const double t_total = best_seconds(repeats, [&] { GridMultigrid levels_of(model); });
  double sink = 0;
  const double t_edges = best_seconds(repeats, [&] { sink += mean_edge_length(mesh); });
  const double t_stars = best_seconds(repeats, [&] {
    sink += static_cast<double>(all_vertex_stars(mesh.connectivity(), mesh.n_points()).entries.size());
  });
  const GridMultigrid levels_of(model);
  std::printf("| %9zu | %7d | %6zu | %8.2f | %8.3f | %5.1f %% | %8.3f | %5.1f %% |\n", mesh.n_cells(),
              mesh.n_live_points(), levels_of.level_sizes()[0], t_total * 1e3, t_edges * 1e3, 100 * t_edges / t_total,
              t_stars * 1e3, 100 * t_stars / t_total);
  std::fflush(stdout);
  if (sink < 0) std::printf("%g\n", sink);
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<int> levels = benchmarks::bisection_levels_argument(argc, argv);
  int petsc_argc = 1;
  PetscSession petsc(&petsc_argc, &argv);
  std::printf("| tetrahedra | vertices | copies | ms per construction | mean edge ms | share | vertex stars ms | share |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (int l : levels) run_block(l);
  return 0;
}
