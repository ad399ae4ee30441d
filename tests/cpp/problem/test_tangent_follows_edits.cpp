// The assembled tangent made from an earlier one after edits (tangent_assembly.hpp, issue 49)
// against one assembled anew: after random sequences of splits, collapses, snaps, insertions,
// flips, vertex removals, dissections and bisections (topology/random_editor.hpp) on a 2D
// square, a cube and a membrane, for every material and both formats, with fixed and sliding
// vertices and a vertex fixed between edits, the sparsity is the same exactly and the values
// agree to round-off (also for the sparsity made alone and then assembled: the path of a
// tangent that depends on the state). The state is the earlier fill's at every vertex the edits did not add, so
// the kept blocks are exact (once a solve moves the state they lag, as kept levels do).
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/csr_matrix.hpp"
#include "core/petsc_util.hpp"
#include "fem/material_fixtures.hpp"
#include "mesh/edit_footprint.hpp"
#include "problem/tangent_checks.hpp"
#include "problem/tangent_assembly.hpp"
#include "topology/edit_checks.hpp"
#include "topology/edited_shapes.hpp"
#include "topology/random_editor.hpp"
#include "topology/refinement_checks.hpp"

using namespace snede;

namespace {

// Whether both matrices store the same entries (rows' starts and columns).
bool same_sparsity(Mat X, Mat Y) {
  const CsrView x(X), y(Y);
  if (x.blocked != y.blocked || x.rows != y.rows) return false;
  return std::equal(x.start, x.start + x.rows + 1, y.start) && std::equal(x.column, x.column + x.start[x.rows], y.column);
}

void set_random_state(Model& model, std::mt19937& random) {
  std::uniform_real_distribution<double> offset(-0.02, 0.02);
  std::vector<double> u(static_cast<std::size_t>(model.n_dofs()));
  for (double& value : u) value = offset(random);
  set_vec_values(model.displacement(), u);
  model.enforce_constraints(model.displacement());
}

}  // namespace

class TangentFollowsEdits : public ::testing::TestWithParam<snede::testing::EditedShape> {};

TEST_P(TangentFollowsEdits, EqualsTheTangentAssembledAnew) {
  for (const Material& material : snede::testing::all_materials())
    for (MatrixFormat format : {MatrixFormat::aij, MatrixFormat::baij}) {
      SCOPED_TRACE(std::string(snede::testing::name_of(material)) + (format == MatrixFormat::aij ? " aij" : " baij"));
      Mesh mesh = snede::testing::edited_shape_mesh(GetParam(), 5, 3);
      ElasticBody body(mesh, material, 1000.0, mesh.is_surface() || mesh.dim() == 2 ? 0.01 : 0.0);
      Model model(body);
      snede::testing::fix_left_slide_right(model);
      model.set_operator_scale(0.37);
      std::mt19937 random(17);
      set_random_state(model, random);
      snede::testing::RandomEditor editor(mesh, 23);
      const double cells = static_cast<double>(mesh.n_cells());
      auto edits = std::make_unique<EditFootprint>(mesh.connectivity());
      auto earlier = std::make_unique<AssembledTangent>(model, format, MembraneTangent::positive_part);
      earlier->assemble(model, model.displacement());
      int edited_vertices = 0;
      for (int round = 0; round < 6; ++round) {
        for (int step = 0; step < 6; ++step) editor.edit(editor.choose(static_cast<double>(mesh.n_cells()) / cells));
        // A vertex fixed, its constraints changed and not the state (Model::fix would also put
        // every vertex on its constraints: a state that moves at a vertex changes every block
        // of the elements around it, which the edit keeps).
        if (round == 3) {
          const VertexId v = mesh.connectivity().element(mesh.cell_ids().back()).simplex.vertex(0);
          model.constraints().fix(std::vector<VertexId>{v}, {});
        }
        edited_vertices += static_cast<int>(edits->vertices().size());
        ASSERT_TRUE(earlier->values_can_follow_edits(model));
        auto next_edits = std::make_unique<EditFootprint>(mesh.connectivity());
        auto edited = std::make_unique<AssembledTangent>(model, *earlier, *edits, model.displacement());
        AssembledTangent sparsity_only(model, *earlier, *edits, nullptr);
        EXPECT_FALSE(sparsity_only.filled());
        sparsity_only.assemble(model, model.displacement());
        AssembledTangent anew(model, format, MembraneTangent::positive_part);
        anew.assemble(model, model.displacement());
        SCOPED_TRACE("round " + std::to_string(round));
        EXPECT_TRUE(same_sparsity(edited->mat(), anew.mat()));
        EXPECT_LT(snede::testing::relative_difference(edited->mat(), anew.mat()), 1e-12);
        EXPECT_TRUE(same_sparsity(sparsity_only.mat(), anew.mat()));
        EXPECT_LT(snede::testing::relative_difference(sparsity_only.mat(), anew.mat()), 1e-12);
        earlier = std::move(edited);
        edits = std::move(next_edits);
      }
      EXPECT_GT(edited_vertices, 20);  // the edits reached the tangent
    }
}

INSTANTIATE_TEST_SUITE_P(Shapes, TangentFollowsEdits, snede::testing::all_edited_shapes(),
                         snede::testing::edited_shape_name);

TEST(TangentFollowsEdits, NotUnderTheSmoothedFormulationAndItsValuesNotBeforeAFill) {
  Mesh mesh = snede::testing::edited_shape_mesh(snede::testing::EditedShape::cube, 5, 3);
  ElasticBody body(mesh, LinearElastic(1e4, 0.3), 1000.0, 0.0, Formulation::smoothed);
  Model model(body);
  AssembledTangent patches(model, MatrixFormat::baij);
  EXPECT_FALSE(patches.can_follow_edits(model));
  patches.assemble(model, model.displacement());
  EXPECT_FALSE(patches.can_follow_edits(model));  // its blocks reach two edges
  EXPECT_FALSE(patches.values_can_follow_edits(model));
  Mesh other = snede::testing::edited_shape_mesh(snede::testing::EditedShape::cube, 5, 3);
  ElasticBody p1_body(other, LinearElastic(1e4, 0.3), 1000.0, 0.0);
  Model p1_model(p1_body);
  AssembledTangent p1(p1_model, MatrixFormat::baij);
  EXPECT_TRUE(p1.can_follow_edits(p1_model));          // its sparsity
  EXPECT_FALSE(p1.values_can_follow_edits(p1_model));  // not filled
  p1.assemble(p1_model, p1_model.displacement());
  EXPECT_TRUE(p1.values_can_follow_edits(p1_model));
  p1_model.set_operator_scale(2.0);
  EXPECT_FALSE(p1.values_can_follow_edits(p1_model));  // filled for another scale
  EXPECT_TRUE(p1.can_follow_edits(p1_model));
}
