// GridMultigrid's interpolation P (the grid levels' coarse space) by its invariants, on a
// bisected box, a box cut halfway and a box cut through (dissected faces), with fixed and
// sliding vertices, and a bisected square: every linear field is P times some coarse vector on
// the free vertices, fixed vertices' rows are zero, a sliding vertex's rows move it along its
// line only, and no column reaches both pieces of a body cut through.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "multigrid/dense_matrix.hpp"
#include "multigrid/grid_multigrid.hpp"
#include "topology/bisection.hpp"
#include "topology/dissect.hpp"
#include "topology/refinement_checks.hpp"

using namespace snede;

namespace {

Mesh bisected(Mesh mesh) {
  Bisection(mesh).refine_uniform(1);
  return mesh;
}

Mesh cut(Mesh mesh, double y_end) {
  // The faces on x = 1/2 with y at most `y_end` (1: the whole plane).
  dissect(mesh, snede::testing::faces_on_plane_x(mesh, 0.5, y_end));
  return mesh;
}

struct Levels {
  Mesh mesh;
  ElasticBody body;
  Model model;
  std::vector<bool> fixed;
  std::vector<std::array<double, 3>> slide_direction;  // zero for a vertex that does not slide
  Eigen::MatrixXd P;

  // Fixes the vertices at y = 0 and slides those at y = 1 along x.
  explicit Levels(Mesh m) : mesh(std::move(m)), body(mesh, LinearElastic(3e3, 0.3), 1000.0, mesh.dim() == 2 ? 0.01 : 0.0), model(body) {
    const int d = mesh.dim();
    fixed.assign(mesh.n_points(), false);
    slide_direction.assign(mesh.n_points(), {0, 0, 0});
    std::vector<VertexId> bottom, top;
    for (VertexId v = 0; v < mesh.n_points(); ++v) {
      if (!mesh.is_vertex(v)) continue;
      if (mesh.point(v)[1] == 0) bottom.push_back(v);
      if (mesh.point(v)[1] == 1) top.push_back(v);
    }
    model.fix(bottom, {});
    for (VertexId v : bottom) fixed[v] = true;
    const std::array<double, 3> along{1, 0, 0};
    model.slide(top, std::span<const double>(along.data(), d));
    for (VertexId v : top) slide_direction[v] = along;
    GridMultigrid levels(model);
    const SolverOptions options("", {});
    PetscHandle<KSP, KSPDestroy> solver;
    SNEDE_PETSC(KSPCreate(PETSC_COMM_SELF, solver.out()));
    PC pc = nullptr;
    SNEDE_PETSC(KSPGetPC(solver, &pc));
    levels.configure(pc, options);
    Mat interpolation = nullptr;
    SNEDE_PETSC(PCMGGetInterpolation(pc, 1, &interpolation));
    P = snede::testing::dense_matrix(interpolation);
  }
  bool is_free(VertexId v) const {
    return mesh.is_vertex(v) && !fixed[v] && slide_direction[v] == std::array<double, 3>{0, 0, 0};
  }
};

void expect_linear_fields_reproduced(const Levels& levels) {
  const int d = levels.mesh.dim();
  std::vector<Eigen::Index> free_rows;
  for (VertexId v = 0; v < levels.mesh.n_points(); ++v)
    if (levels.is_free(v))
      for (int i = 0; i < d; ++i) free_rows.push_back(v * d + i);
  const Eigen::MatrixXd P_free = levels.P(free_rows, Eigen::all);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> least_squares(P_free);
  // Each component of the field is 1, x, y or z in turn.
  for (int component = 0; component < d; ++component)
    for (int variable = -1; variable < d; ++variable) {
      Eigen::VectorXd field(static_cast<Eigen::Index>(free_rows.size()));
      for (std::size_t r = 0; r < free_rows.size(); ++r) {
        const auto v = static_cast<VertexId>(free_rows[r] / d);
        const auto i = static_cast<int>(free_rows[r] % d);
        field[static_cast<Eigen::Index>(r)] = i != component ? 0.0 : variable < 0 ? 1.0 : levels.mesh.point(v)[variable];
      }
      const Eigen::VectorXd coarse = least_squares.solve(field);
      EXPECT_LT((P_free * coarse - field).norm(), 1e-10 * field.norm()) << "component " << component << ", variable " << variable;
    }
}

void expect_constrained_rows(const Levels& levels) {
  const int d = levels.mesh.dim();
  for (VertexId v = 0; v < levels.mesh.n_points(); ++v) {
    if (levels.fixed[v]) EXPECT_EQ(levels.P.middleRows(v * d, d).norm(), 0.0) << "fixed vertex " << v;
    const auto& along = levels.slide_direction[v];
    if (along == std::array<double, 3>{0, 0, 0}) continue;
    for (int i = 0; i < d; ++i)
      if (along[i] == 0) EXPECT_EQ(levels.P.row(v * d + i).norm(), 0.0) << "sliding vertex " << v;
    EXPECT_GT(levels.P.middleRows(v * d, d).norm(), 0.0) << "sliding vertex " << v;
  }
}

}  // namespace

TEST(GridMultigrid, BisectedBoxReproducesLinearFields) {
  const Levels levels(bisected(snede::testing::kuhn_cube(4)));
  expect_linear_fields_reproduced(levels);
  expect_constrained_rows(levels);
}

TEST(GridMultigrid, BoxCutHalfwayReproducesLinearFields) {
  const Levels levels(cut(snede::testing::kuhn_cube(6), 0.5));
  expect_linear_fields_reproduced(levels);
  expect_constrained_rows(levels);
}

TEST(GridMultigrid, BisectedSquareReproducesLinearFields) {
  const Levels levels(bisected(snede::testing::right_triangle_square(6)));
  expect_linear_fields_reproduced(levels);
  expect_constrained_rows(levels);
}

TEST(GridMultigrid, NoColumnReachesBothPiecesOfABoxCutThrough) {
  const Levels levels(cut(snede::testing::kuhn_cube(6), 1.0));
  const int d = levels.mesh.dim();
  // The pieces are the sides of x = 1/2; a vertex on the plane lies in the piece of its cells.
  std::vector<int> piece(levels.mesh.n_points(), -1);
  const std::vector<VertexId> corners = levels.mesh.cells();
  for (std::size_t c = 0; c < corners.size(); c += 4) {
    double x = 0;
    for (int a = 0; a < 4; ++a) x += levels.mesh.point(corners[c + a])[0] / 4;
    for (int a = 0; a < 4; ++a) piece[corners[c + a]] = x > 0.5 ? 1 : 0;
  }
  int columns_on_plane = 0;
  for (Eigen::Index column = 0; column < levels.P.cols(); ++column) {
    std::set<int> reached;
    for (Eigen::Index row = 0; row < levels.P.rows(); ++row)
      if (levels.P(row, column) != 0) reached.insert(piece[row / d]);
    EXPECT_EQ(reached.size(), 1u) << "column " << column;
    bool on_plane = false;
    for (Eigen::Index row = 0; row < levels.P.rows(); ++row)
      on_plane = on_plane || (levels.P(row, column) != 0 && levels.mesh.point(static_cast<VertexId>(row / d))[0] == 0.5);
    columns_on_plane += on_plane;
  }
  EXPECT_GT(columns_on_plane, 0);
  expect_linear_fields_reproduced(levels);
  expect_constrained_rows(levels);
}
