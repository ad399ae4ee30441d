// Grid levels made from the earlier ones after edits (GridMultigrid::follow_edits, issue 49)
// against levels made anew on the same grid: after random sequences of splits, collapses,
// snaps, insertions, flips, vertex removals, dissections and bisections (random_editor.hpp) on a
// 2D square, a cube and a membrane (three interior faces opened at once in one round), with fixed and sliding vertices
// and a vertex fixed between edits, the interpolation is the same entry for entry, coarse
// numbering included.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "core/csr_matrix.hpp"
#include "core/error.hpp"
#include "multigrid/grid_multigrid.hpp"
#include "problem/tangent_checks.hpp"
#include "topology/edit_checks.hpp"
#include "topology/edited_shapes.hpp"
#include "topology/random_editor.hpp"
#include "topology/refinement_checks.hpp"

using namespace snede;

namespace {

// The interpolation the levels give a PCMG.
class Interpolation {
 public:
  explicit Interpolation(Multigrid& levels) {
    SNEDE_PETSC(KSPCreate(PETSC_COMM_SELF, solver_.out()));
    PC pc = nullptr;
    SNEDE_PETSC(KSPGetPC(solver_, &pc));
    levels.configure(pc, SolverOptions("", {}), {});
    SNEDE_PETSC(PCMGGetInterpolation(pc, 1, &P_));
  }
  Mat mat() const { return P_; }

 private:
  PetscHandle<KSP, KSPDestroy> solver_;
  Mat P_ = nullptr;
};

// Whether two matrices have the same size, the same stored entries and the same values.
bool identical(Mat X, Mat Y) {
  PetscInt xr = 0, xc = 0, yr = 0, yc = 0;
  SNEDE_PETSC(MatGetSize(X, &xr, &xc));
  SNEDE_PETSC(MatGetSize(Y, &yr, &yc));
  if (xr != yr || xc != yc) return false;
  const CsrView x(X), y(Y);
  return std::equal(x.start, x.start + x.rows + 1, y.start) &&
         std::equal(x.column, x.column + x.start[x.rows], y.column) &&
         std::equal(x.value, x.value + x.start[x.rows], y.value);
}

}  // namespace

class GridLevelsFollowEdits : public ::testing::TestWithParam<snede::testing::EditedShape> {};

TEST_P(GridLevelsFollowEdits, EqualTheLevelsMadeAnewOnTheSameGrid) {
  Mesh mesh = snede::testing::edited_shape_mesh(GetParam(), 6, 4);
  ElasticBody body(mesh, LinearElastic(3e3, 0.3), 1000.0, mesh.is_surface() || mesh.dim() == 2 ? 0.01 : 0.0);
  Model model(body);
  snede::testing::fix_left_slide_right(model);
  snede::testing::RandomEditor editor(mesh, 29);
  const double cells = static_cast<double>(mesh.n_cells());
  std::unique_ptr<Multigrid> earlier = std::make_unique<GridMultigrid>(model);
  const GridGeometry grid = static_cast<GridMultigrid&>(*earlier).geometry();
  std::size_t most_copies = 0;
  for (int round = 0; round < 8; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    for (int step = 0; step < 6; ++step) editor.edit(editor.choose(static_cast<double>(mesh.n_cells()) / cells));
    if (round == 3) {
      const VertexId v = mesh.connectivity().element(mesh.cell_ids().back()).simplex.vertex(0);
      model.constraints().fix(std::vector<VertexId>{v}, {});
    }
    if (round == 5)
      for (int cut = 0; cut < 3; ++cut) editor.edit(snede::testing::dissection);  // interior faces opened
    std::unique_ptr<Multigrid> edited = earlier->follow_edits();
    ASSERT_TRUE(edited);
    GridMultigrid anew(model, grid);
    EXPECT_TRUE(identical(Interpolation(*edited).mat(), Interpolation(anew).mat()));
    EXPECT_EQ(edited->level_unknowns(), anew.level_unknowns());
    most_copies = std::max(most_copies, edited->level_sizes().front());
    earlier = std::move(edited);
  }
  EXPECT_GT(most_copies, 4u);  // a coarse level with several node copies
}

INSTANTIATE_TEST_SUITE_P(Shapes, GridLevelsFollowEdits, snede::testing::all_edited_shapes(),
                         snede::testing::edited_shape_name);
