// The solver's check that constraints hold every piece, following the mesh's edits (issue 49:
// labels changed only where the mesh changed), against the same check made from scratch on the
// edited mesh (connected_components): after random splits, collapses, snaps, insertions, flips,
// removals, dissections and bisections (random_editor.hpp) on a square, a cube and a membrane,
// both give the same verdict and the same report, for constraints that hold the body and for
// constraints that do not; a hinge counts for both pieces it joins; and a notch is settled
// without labelling the whole mesh, while a cut through the body is found to free a piece.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mesh/traversal.hpp"
#include "problem/piece_holding.hpp"
#include "topology/edited_shapes.hpp"
#include "topology/random_editor.hpp"
#include "topology/refinement_checks.hpp"
#include "topology/section_cuts.hpp"
#include "topology/split_edge.hpp"

using namespace snede;

namespace {

// Vertices of cells on the plane x = 0 (the squares', cubes' and membranes' left side).
std::vector<VertexId> left_side(const Mesh& mesh) {
  std::vector<VertexId> left;
  for (ElementId e : mesh.cell_ids())
    for (VertexId v : mesh.connectivity().element(e).simplex.vertices())
      if (mesh.point(v)[0] == 0) left.push_back(v);
  std::sort(left.begin(), left.end());
  left.erase(std::unique(left.begin(), left.end()), left.end());
  return left;
}

// The corners of a cell around the vertex of highest id in a cell (the newest an edit added).
std::vector<VertexId> corners_at_newest_vertex(const Mesh& mesh) {
  const Connectivity& c = mesh.connectivity();
  for (VertexId v = mesh.n_points() - 1; v >= 0; --v)
    if (c.n_vertex_uses(v) > 0) {
      const auto corners = c.element(c.vertex_element(v)).simplex.vertices();
      return {corners.begin(), corners.end()};
    }
  throw std::logic_error("no vertex in a cell");
}

Constraints fixed(const Mesh& mesh, const std::vector<VertexId>& vertices) {
  Constraints constraints(mesh.dim());
  constraints.resize(mesh.n_points());
  constraints.fix(vertices, {});
  return constraints;
}

void expect_same(const std::vector<LoosePiece>& followed, const std::vector<LoosePiece>& anew) {
  ASSERT_EQ(followed.size(), anew.size());
  for (std::size_t i = 0; i < anew.size(); ++i) {
    EXPECT_EQ(followed[i].piece, anew[i].piece);
    EXPECT_EQ(followed[i].pieces, anew[i].pieces);
    EXPECT_EQ(followed[i].cells, anew[i].cells);
    EXPECT_EQ(followed[i].first_cell, anew[i].first_cell);
    EXPECT_EQ(followed[i].constrained_components, anew[i].constrained_components);
    EXPECT_EQ(followed[i].rigid_motions_stopped, anew[i].rigid_motions_stopped);
  }
}

}  // namespace

class PieceHoldingFollowsEdits : public ::testing::TestWithParam<snede::testing::EditedShape> {};

TEST_P(PieceHoldingFollowsEdits, GivesTheVerdictAndReportOfACheckFromScratch) {
  Mesh mesh = snede::testing::edited_shape_mesh(GetParam(), 6, 4);
  // `followed` is also asked about constraints that hold nothing, which makes it label every piece
  // again; `kept` only about constraints that hold the body, so its labels follow every round's
  // edits from the first question on.
  PieceHolding followed(mesh, PieceHolding::FollowEdits{}), kept(mesh, PieceHolding::FollowEdits{});
  snede::testing::RandomEditor editor(mesh, 31);
  const double cells = static_cast<double>(mesh.n_cells());
  const std::vector<VertexId> left = left_side(mesh);
  ASSERT_GE(left.size(), 3u);
  int pieces_before = 1;
  for (PieceHolding* holding : {&followed, &kept})
    EXPECT_TRUE(holding->loose_pieces(fixed(mesh, left)).empty());  // labels every piece, once
  for (int round = 0; round < 10; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    for (int step = 0; step < 5; ++step) editor.edit(editor.choose(static_cast<double>(mesh.n_cells()) / cells));
    if (round % 3 == 2)
      for (int cut = 0; cut < 4; ++cut) editor.edit(snede::testing::dissection);  // interior faces opened
    const int pieces = connected_components(mesh.connectivity()).second;
    // The left side held (the body is held unless an edit freed a part), the corners of a cell at
    // the newest vertex held (which only its piece found again can credit), and one vertex held
    // (no piece is: it can turn about the vertex).
    const std::vector<Constraints> holding_constraints{fixed(mesh, left_side(mesh)),
                                                       fixed(mesh, corners_at_newest_vertex(mesh))};
    for (const Constraints& constraints : holding_constraints) {
      const std::vector<LoosePiece> anew = PieceHolding(mesh).loose_pieces(constraints);
      const std::size_t labellings = kept.whole_labellings();
      expect_same(kept.loose_pieces(constraints), anew);
      expect_same(followed.loose_pieces(constraints), anew);
      // Held, and no piece split off since the last question: settled where the edits were.
      if (anew.empty() && pieces == pieces_before) EXPECT_EQ(kept.whole_labellings(), labellings);
    }
    const Constraints one_vertex = fixed(mesh, {left.front()});
    expect_same(followed.loose_pieces(one_vertex), PieceHolding(mesh).loose_pieces(one_vertex));
    pieces_before = pieces;
  }
}

// A triangle and a pair of triangles that share only vertex 2 (a hinge): the fixed hinge counts
// for both pieces, also after an edit that changes the hinge's star.
TEST(PieceHoldingFollowsEdits, AHingeCountsForBothPiecesAfterAnEditAroundIt) {
  Mesh mesh = snede::testing::mesh_of(2, {0, 0, 1, 0, 1, 1, 2, 1, 2, 2, 3, 2}, {{0, 1, 2}, {2, 3, 4}, {3, 5, 4}});
  PieceHolding followed(mesh, PieceHolding::FollowEdits{});
  // Two fixed points stop a plane body's three rigid motions: the hinge and vertex 0 hold the
  // piece {0, 1, 2}, the hinge and vertex 4 the piece {2, 3, 4, 5}; without 4 the second turns.
  EXPECT_TRUE(followed.loose_pieces(fixed(mesh, {0, 2, 4})).empty());
  EXPECT_EQ(followed.loose_pieces(fixed(mesh, {0, 2})).size(), 1u);
  const std::size_t labellings = followed.whole_labellings();
  split_edge(mesh, 2, 3, 0.5);  // the second piece's triangles around the hinge change
  const Constraints hinge_and_ends = fixed(mesh, {0, 2, 4});
  expect_same(followed.loose_pieces(hinge_and_ends), PieceHolding(mesh).loose_pieces(hinge_and_ends));
  EXPECT_TRUE(followed.loose_pieces(hinge_and_ends).empty());
  EXPECT_EQ(followed.whole_labellings(), labellings) << "the hinge was not credited to both pieces";
}

INSTANTIATE_TEST_SUITE_P(Shapes, PieceHoldingFollowsEdits, snede::testing::all_edited_shapes(),
                         snede::testing::edited_shape_name);

TEST(PieceHoldingFollowsEdits, ANotchKeepsTheLabelsAndACutThroughFreesAPiece) {
  Mesh mesh = snede::testing::kuhn_cube(8, 8.0);
  PieceHolding followed(mesh, PieceHolding::FollowEdits{});
  const Constraints left = fixed(mesh, left_side(mesh));
  EXPECT_TRUE(followed.loose_pieces(left).empty());
  EXPECT_EQ(followed.whole_labellings(), 1u);
  // A notch: the section x = 4 opened within one cell of the edge y = z = 0.
  const auto [notch, rest] = snede::testing::notch_and_rest(mesh, 4);
  ASSERT_FALSE(notch.empty());
  snede::testing::dissect_faces(mesh, notch);
  EXPECT_TRUE(followed.loose_pieces(fixed(mesh, left_side(mesh))).empty());
  EXPECT_EQ(followed.whole_labellings(), 1u) << "a notch labelled every piece again";
  // The rest of the section: the half x ≥ 4 is free.
  snede::testing::dissect_faces(mesh, rest);
  const Constraints still_left = fixed(mesh, left_side(mesh));
  const std::vector<LoosePiece> anew = PieceHolding(mesh).loose_pieces(still_left);
  ASSERT_EQ(anew.size(), 1u);
  EXPECT_EQ(anew.front().pieces, 2);
  EXPECT_EQ(anew.front().cells, mesh.n_cells() / 2);
  expect_same(followed.loose_pieces(still_left), anew);
  EXPECT_GT(followed.whole_labellings(), 1u);
}
