// Benchmark (not a test): what following one cut move costs the solver's structures, made anew
// against made from the earlier ones (issue 49), in milliseconds and in work units (1 WU = one
// product of the mesh's assembled AIJ tangent, the fastest of 30, timed in this process).
//
//     build/cpp/follow_edit [levels ...]   (default: 0 2; a 16³ Kuhn box of 24 576 tetrahedra,
//                                           uniformly bisected `levels` times)
//
// The block is a 0.1 m cube with its bottom face fixed, cut along half of its mid-plane x = 0.05
// (y ≤ 0.05); the structures are made for it, then the move cuts one more band of that plane
// (0.05 < y ≤ 0.05 + 0.1/16) and each structure follows: the assembled BAIJ tangent (sparsity
// and values) and the grid levels (interpolation; on the grid of the first build, and with the
// grid chosen for the mesh as before issue 49). Each figure is the fastest of several.
#include <algorithm>
#include <array>
#include <cstdio>
#include <set>
#include <vector>

#include "best_seconds.hpp"
#include "bisection_levels_argument.hpp"
#include "core/petsc_session.hpp"
#include "core/petsc_util.hpp"
#include "fem/elastic_body.hpp"
#include "mesh/edit_footprint.hpp"
#include "multigrid/grid_multigrid.hpp"
#include "problem/model.hpp"
#include "problem/tangent_assembly.hpp"
#include "topology/bisection.hpp"
#include "topology/dissect.hpp"
#include "topology/refinement_checks.hpp"

namespace {

using namespace snede;
using benchmarks::best_seconds;

constexpr double side = 0.1;

// The faces of `to` (vertex triples) that are not in `from`.
std::vector<VertexId> faces_not_in(const std::vector<VertexId>& to, const std::vector<VertexId>& from) {
  std::set<std::array<VertexId, 3>> earlier;
  for (std::size_t k = 0; k < from.size(); k += 3) earlier.insert({from[k], from[k + 1], from[k + 2]});
  std::vector<VertexId> band;
  for (std::size_t k = 0; k < to.size(); k += 3)
    if (!earlier.count({to[k], to[k + 1], to[k + 2]})) band.insert(band.end(), {to[k], to[k + 1], to[k + 2]});
  return band;
}

void run_block(int levels) {
  Mesh mesh = testing::kuhn_cube(16, side);
  if (levels > 0) Bisection(mesh).refine_uniform(levels);
  const std::vector<VertexId> half = testing::faces_on_plane_x(mesh, side / 2, side / 2);
  const std::vector<VertexId> move = faces_not_in(testing::faces_on_plane_x(mesh, side / 2, side / 2 + side / 16), half);
  dissect(mesh, half);
  ElasticBody body(mesh, LinearElastic(3e3, 0.3), 1000.0, 0.0);
  Model model(body);
  std::vector<VertexId> bottom;
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v) && mesh.point(v)[2] == 0) bottom.push_back(v);
  model.fix(bottom, {});
  Vec u = model.displacement();

  AssembledTangent earlier_tangent(model, MatrixFormat::baij);
  earlier_tangent.assemble(model, u);
  GridMultigrid earlier_levels(model);
  const EditFootprint edits(mesh.connectivity());
  dissect(mesh, move);  // the move
  u = model.displacement();  // reissued for the new vertices

  const int repeats = mesh.n_cells() > 50000 ? 10 : 30;
  const double tangent_anew = best_seconds(repeats, [&] {
    AssembledTangent tangent(model, MatrixFormat::baij);
    tangent.assemble(model, u);
  });
  const double tangent_edited = best_seconds(repeats, [&] { AssembledTangent tangent(model, earlier_tangent, edits, u); });
  const double levels_anew_new_grid = best_seconds(repeats, [&] { GridMultigrid levels(model); });
  const double levels_anew = best_seconds(repeats, [&] { GridMultigrid levels(model, earlier_levels.geometry()); });
  const double levels_edited = best_seconds(repeats, [&] { earlier_levels.follow_edits(); });

  AssembledTangent aij(model, MatrixFormat::aij);
  aij.assemble(model, u);
  VecHandle x, y;
  SNEDE_PETSC(MatCreateVecs(aij.mat(), x.out(), y.out()));
  SNEDE_PETSC(VecSet(x, 1.0));
  const double wu = best_seconds(30, [&] { SNEDE_PETSC(MatMult(aij.mat(), x, y)); });

  std::printf("| %9zu | %7zu | %5zu | %.3f | %6.2f | %6.2f | %5.1f | %5.1f | %6.2f | %6.2f | %6.2f | %5.1f | %5.1f |\n",
              mesh.n_cells(), edits.vertices().size(), move.size() / 3, wu * 1e3, tangent_anew * 1e3,
              tangent_edited * 1e3, tangent_anew / wu, tangent_edited / wu, levels_anew_new_grid * 1e3,
              levels_anew * 1e3, levels_edited * 1e3, levels_anew / wu, levels_edited / wu);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<int> levels = benchmarks::bisection_levels_argument(argc, argv);
  int petsc_argc = 1;
  PetscSession petsc(&petsc_argc, &argv);
  std::printf("| tetrahedra | vertices touched | faces cut | WU ms | tangent anew ms | edited ms | anew WU | edited WU "
              "| levels on a new grid ms | anew ms | edited ms | anew WU | edited WU |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int l : levels) run_block(l);
  return 0;
}
