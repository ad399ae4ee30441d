// rank_aggregation_levels' interpolations by their invariants, on boxes distributed over
// MPI_COMM_WORLD: one rank in the discovered tests, 2 and 3 in rank_aggregation_mpi2/3
// (CMakeLists.txt). On every rank: its rows of each interpolation reach only its own columns,
// every rigid motion restricted to the free dofs is the interpolation of some coarse vector
// (to round-off) from every level, fixed dofs' rows are zero, the columns are independent, and
// the levels shrink. Then CG preconditioned by PCMG on these levels against Jacobi's CG on an
// elastic box's assembled tangent. Every check reduces over the ranks first, so all ranks
// reach the same verdict and make the same collective calls.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "core/error.hpp"
#include "fem/elastic_body.hpp"
#include "fem/linear_elastic.hpp"
#include "mesh/distributed_mesh.hpp"
#include "mesh/distributed_box.hpp"
#include "multigrid/dense_matrix.hpp"
#include "problem/distributed_assembly.hpp"
#include "multigrid/rank_aggregation.hpp"

using namespace snede;

namespace {

using Matrix = Eigen::MatrixXd;
using snede::testing::distributed_box;
using snede::testing::unit_box;
using snede::testing::world_rank;

// 1 on every dof of the local vertices on the face y = 0.
std::vector<std::uint8_t> bottom_fixed(const DistributedMesh& part) {
  const int d = part.local->dim();
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(part.local->n_points()) * d, 0);
  for (VertexId v = 0; v < part.local->n_points(); ++v)
    if (part.local->point(v)[1] == 0)
      for (int k = 0; k < d; ++k) fixed[static_cast<std::size_t>(v) * d + k] = 1;
  return fixed;
}

// This rank's rows and columns of P, dense; entries in other ranks' columns are counted.
Matrix local_block(Mat P, std::size_t& off_rank_entries) {
  PetscInt row_start = 0, row_end = 0, column_start = 0, column_end = 0;
  SNEDE_PETSC(MatGetOwnershipRange(P, &row_start, &row_end));
  SNEDE_PETSC(MatGetOwnershipRangeColumn(P, &column_start, &column_end));
  Matrix block = Matrix::Zero(row_end - row_start, column_end - column_start);
  for (PetscInt r = row_start; r < row_end; ++r) {
    PetscInt n_entries = 0;
    const PetscInt* columns = nullptr;
    const PetscScalar* values = nullptr;
    SNEDE_PETSC(MatGetRow(P, r, &n_entries, &columns, &values));
    for (PetscInt e = 0; e < n_entries; ++e) {
      if (columns[e] < column_start || columns[e] >= column_end) {
        ++off_rank_entries;
        continue;
      }
      block(r - row_start, columns[e] - column_start) = values[e];
    }
    SNEDE_PETSC(MatRestoreRow(P, r, &n_entries, &columns, &values));
  }
  return block;
}

// The body's rigid motions (translations, then rotations about the origin) at this rank's
// rows of the fine level (owned vertex v's dof k at global_number[v]·dim + k), zero on fixed dofs.
Matrix free_rigid_modes(const DistributedMesh& part, const std::vector<std::uint8_t>& fixed, PetscInt row_start) {
  const int d = part.local->dim(), n_modes = d == 3 ? 6 : 3;
  std::size_t n_owned = 0;
  for (std::uint8_t owned : part.owned) n_owned += owned;
  Matrix modes = Matrix::Zero(static_cast<Eigen::Index>(n_owned) * d, n_modes);
  for (VertexId v = 0; v < part.local->n_points(); ++v) {
    if (!part.owned[v]) continue;
    const auto x = part.local->point(v);
    Eigen::Matrix<double, 3, 6> motion = Eigen::Matrix<double, 3, 6>::Zero();
    motion.leftCols(3).setIdentity();
    if (d == 3) {
      // ω × x for ω = e_0, e_1, e_2.
      motion.col(3) << 0, -x[2], x[1];
      motion.col(4) << x[2], 0, -x[0];
      motion.col(5) << -x[1], x[0], 0;
    } else {
      motion(0, 2) = -x[1];
      motion(1, 2) = x[0];
    }
    for (int k = 0; k < d; ++k) {
      if (fixed[static_cast<std::size_t>(v) * d + k]) continue;
      const Eigen::Index row = part.global_number[v] * d + k - row_start;
      for (int m = 0; m < n_modes; ++m) modes(row, m) = motion(k, m);
    }
  }
  return modes;
}

// What examine() finds over all ranks.
struct Findings {
  double worst_rigid_residual = 0;          // ‖C c − r‖ / ‖r‖ at the least-squares c, any level and mode
  double smallest_gram_eigenvalue = std::numeric_limits<double>::infinity();  // of CᵀC over the levels
  double largest_fixed_row_entry = 0;
  std::uint64_t off_rank_entries = 0;
  std::uint64_t layout_mismatches = 0;      // a level's columns on a rank that are not the coarser level's rows
};

// Collective. C_l, the interpolation from level l to the fine one, restricted to this rank's
// rows and columns (the product of the ranks' diagonal blocks, which is all of it when no
// entry is off the rank), checked level by level and reduced over the ranks.
Findings examine(const DistributedMesh& part, const std::vector<std::uint8_t>& fixed, const RankAggregationLevels& levels) {
  Findings local;
  const int d = part.local->dim();
  PetscInt row_start = 0, row_end = 0;
  SNEDE_PETSC(MatGetOwnershipRange(levels.interpolations.back(), &row_start, &row_end));
  const Matrix modes = free_rigid_modes(part, fixed, row_start);
  local.layout_mismatches += modes.rows() != row_end - row_start;
  Matrix C = Matrix::Identity(row_end - row_start, row_end - row_start);
  for (auto P = levels.interpolations.rbegin(); P != levels.interpolations.rend(); ++P) {
    std::size_t off_rank = 0;
    const Matrix block = local_block(*P, off_rank);
    local.off_rank_entries += off_rank;
    if (block.rows() != C.cols()) {
      ++local.layout_mismatches;
      break;
    }
    C = C * block;
    if (C.cols() == 0) continue;
    const Eigen::ColPivHouseholderQR<Matrix> least_squares(C);
    for (Eigen::Index m = 0; m < modes.cols(); ++m) {
      if (modes.col(m).norm() == 0) continue;
      const Eigen::VectorXd c = least_squares.solve(modes.col(m));
      local.worst_rigid_residual = std::max(local.worst_rigid_residual, (C * c - modes.col(m)).norm() / modes.col(m).norm());
    }
    const Eigen::SelfAdjointEigenSolver<Matrix> gram(C.transpose() * C, Eigen::EigenvaluesOnly);
    local.smallest_gram_eigenvalue = std::min(local.smallest_gram_eigenvalue, gram.eigenvalues().minCoeff());
    for (VertexId v = 0; v < part.local->n_points(); ++v)
      for (int k = 0; k < d; ++k)
        if (part.owned[v] && fixed[static_cast<std::size_t>(v) * d + k])
          local.largest_fixed_row_entry = std::max(local.largest_fixed_row_entry,
                                                   C.row(part.global_number[v] * d + k - row_start).cwiseAbs().maxCoeff());
  }
  Findings all;
  MPI_Allreduce(&local.worst_rigid_residual, &all.worst_rigid_residual, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&local.smallest_gram_eigenvalue, &all.smallest_gram_eigenvalue, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&local.largest_fixed_row_entry, &all.largest_fixed_row_entry, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&local.off_rank_entries, &all.off_rank_entries, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&local.layout_mismatches, &all.layout_mismatches, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

void expect_sound_levels(const DistributedMesh& part, const std::vector<std::uint8_t>& fixed,
                         const RankAggregationLevels& levels) {
  ASSERT_FALSE(levels.interpolations.empty());
  ASSERT_EQ(levels.global_unknowns.size(), levels.interpolations.size() + 1);
  EXPECT_EQ(levels.global_unknowns.back(), part.n_global_vertices * part.local->dim());
  for (std::size_t l = 0; l < levels.interpolations.size(); ++l) {
    PetscInt rows = 0, columns = 0;
    SNEDE_PETSC(MatGetSize(levels.interpolations[l], &rows, &columns));
    EXPECT_EQ(columns, levels.global_unknowns[l]);
    EXPECT_EQ(rows, levels.global_unknowns[l + 1]);
    EXPECT_LT(levels.global_unknowns[l], levels.global_unknowns[l + 1]) << "level " << l << " does not shrink";
    EXPECT_GT(levels.global_unknowns[l], 0);
  }
  const Findings found = examine(part, fixed, levels);
  EXPECT_EQ(found.layout_mismatches, 0u);
  EXPECT_EQ(found.off_rank_entries, 0u);
  EXPECT_LT(found.worst_rigid_residual, 1e-12);
  EXPECT_GT(found.smallest_gram_eigenvalue, 1e-8);  // full column rank
  EXPECT_EQ(found.largest_fixed_row_entry, 0.0);
}

TEST(RankAggregation, LevelsOfABoxReproduceEveryRigidMotionOnEveryRank) {
  // Few direct unknowns, so that aggregates are aggregated again.
  for (const auto& [dim, n, direct_unknowns] : {std::tuple{2, 24, PetscInt{40}}, std::tuple{3, 8, PetscInt{100}}}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    const DistributedMesh part = distributed_box(dim, n);
    const std::vector<std::uint8_t> fixed = bottom_fixed(part);
    const RankAggregationLevels levels = rank_aggregation_levels(part, fixed, 2.5, 0, direct_unknowns);
    EXPECT_GE(levels.interpolations.size(), 2u);
    expect_sound_levels(part, fixed, levels);
  }
}

TEST(RankAggregation, FreeBoxAndCoarserWidths) {
  // No fixed dof: every aggregate keeps all its rigid motions.
  const DistributedMesh part = distributed_box(3, 6);
  const std::vector<std::uint8_t> free(static_cast<std::size_t>(part.local->n_points()) * 3, 0);
  for (double width : {1.5, 4.0}) {
    SCOPED_TRACE("width " + std::to_string(width));
    const RankAggregationLevels levels = rank_aggregation_levels(part, free, width, 0, 30);
    expect_sound_levels(part, free, levels);
    EXPECT_EQ(levels.global_unknowns.front() % 6, 0) << "a free aggregate has 6 rigid motions";
  }
}

TEST(RankAggregation, StopsAtTheDirectLimitOrAtMaxLevels) {
  const DistributedMesh part = distributed_box(3, 8);
  const std::vector<std::uint8_t> fixed = bottom_fixed(part);
  const RankAggregationLevels by_default = rank_aggregation_levels(part, fixed, 2.5);
  EXPECT_LE(by_default.global_unknowns.front(), default_direct_unknowns);
  const RankAggregationLevels two = rank_aggregation_levels(part, fixed, 2.5, 2, 1);
  EXPECT_EQ(two.interpolations.size(), 1u);
  expect_sound_levels(part, fixed, two);
}

TEST(RankAggregation, AMeshSmallerThanTheRanksLeavesSomeWithoutUnknowns) {
  // Two triangles: on 3 ranks one has no cell, no vertex and no coarse unknown, yet takes part.
  const DistributedMesh part = distributed_box(2, 1);
  const std::vector<std::uint8_t> free(static_cast<std::size_t>(part.local->n_points()) * 2, 0);
  const RankAggregationLevels levels = rank_aggregation_levels(part, free, 2.5);
  expect_sound_levels(part, free, levels);
}

TEST(RankAggregation, BadInputsThrowOnEveryRank) {
  const DistributedMesh part = distributed_box(2, 4);
  const std::vector<std::uint8_t> fixed = bottom_fixed(part);
  for (double width : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()})
    EXPECT_THROW(rank_aggregation_levels(part, fixed, width), std::invalid_argument) << width;
  for (int max_levels : {1, -2}) EXPECT_THROW(rank_aggregation_levels(part, fixed, 2.5, max_levels), std::invalid_argument);
  const std::vector<std::uint8_t> short_by_one(fixed.begin(), fixed.end() - 1);
  EXPECT_THROW(rank_aggregation_levels(part, short_by_one, 2.5), std::invalid_argument);
}

// Collective: the whole of a distributed matrix, dense, on every rank.
Matrix gathered(Mat A) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  Mat whole = nullptr;
  SNEDE_PETSC(MatCreateRedundantMatrix(A, ranks, MPI_COMM_NULL, MAT_INITIAL_MATRIX, &whole));
  Matrix dense = snede::testing::dense_matrix(whole);
  MatDestroy(&whole);
  return dense;
}

// Collective: the fine level's row of each serial vertex (PETSc's number, from its owner).
std::vector<Eigen::Index> vertex_rows(const DistributedMesh& part, VertexId n_serial_vertices) {
  std::vector<std::int64_t> pairs;
  for (VertexId v = 0; v < part.local->n_points(); ++v)
    if (part.owned[v]) pairs.insert(pairs.end(), {part.global_vertex[v], part.global_number[v]});
  int count = static_cast<int>(pairs.size()), ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(counts.size(), 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(static_cast<std::size_t>(offsets.back() + counts.back()));
  MPI_Allgatherv(pairs.data(), count, MPI_INT64_T, all.data(), counts.data(), offsets.data(), MPI_INT64_T, MPI_COMM_WORLD);
  std::vector<Eigen::Index> number(static_cast<std::size_t>(n_serial_vertices));
  for (std::size_t k = 0; k < all.size(); k += 2) number[static_cast<std::size_t>(all[k])] = all[k + 1];
  return number;
}

TEST(RankAggregation, TheSmoothedFirstLevelIsOneJacobiStepOfTheWholeMeshsGraphLaplacian) {
  // Rebuilt here from the serial box that every rank makes: Π (I − ω D⁻¹ L) T with L the graph
  // Laplacian of the whole mesh (an edge weighs the cells that share it), so an interface vertex's
  // row must count the other ranks' cells too.
  const int d = 3, n = 4;
  const Mesh serial = unit_box(d, n);
  const DistributedMesh part = distribute_mesh(MPI_COMM_WORLD, world_rank() == 0 ? &serial : nullptr);
  const std::vector<std::uint8_t> fixed = bottom_fixed(part);
  const RankAggregationLevels plain = rank_aggregation_levels(part, fixed, 2.5, 2);
  const RankAggregationLevels smoothed = rank_aggregation_levels(part, fixed, 2.5, 2, default_direct_unknowns, true);
  ASSERT_EQ(smoothed.global_unknowns, plain.global_unknowns);
  const Matrix T = gathered(plain.interpolations.back()), P = gathered(smoothed.interpolations.back());
  const std::vector<Eigen::Index> number = vertex_rows(part, serial.n_points());

  const Eigen::Index n_vertices = serial.n_points();
  Matrix adjacency = Matrix::Zero(n_vertices, n_vertices);
  const std::vector<VertexId> cells = serial.cells();
  for (std::size_t c = 0; c < cells.size(); c += 4)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (i != j) adjacency(number[cells[c + i]], number[cells[c + j]]) += 1.0;
  Matrix S = Matrix::Zero(n_vertices * d, n_vertices * d);
  const double omega = 2.0 / 3.0;
  for (VertexId v = 0; v < n_vertices; ++v) {
    const Eigen::Index a = number[static_cast<std::size_t>(v)];
    const double kept = serial.point(v)[1] == 0 ? 0.0 : 1.0;  // Π: the bottom is fixed
    const double degree = adjacency.row(a).sum();
    for (Eigen::Index b = 0; b < n_vertices; ++b) {
      const double factor = b == a ? 1.0 - omega : omega * adjacency(a, b) / degree;
      for (int k = 0; k < d; ++k) S(a * d + k, b * d + k) = kept * factor;
    }
  }
  const Matrix expected = S * T;
  EXPECT_LT((P - expected).cwiseAbs().maxCoeff(), 1e-14 * expected.cwiseAbs().maxCoeff());
}

TEST(RankAggregation, TheSecondLevelIsOneJacobiStepOfTheGalerkinLaplacian) {
  // P₂ = (I − ω D₁⁻¹ A₁) T₂ with A₁ = P₁ᵀ (L ⊗ I) P₁, rebuilt here densely from the gathered
  // interpolations and the serial mesh's graph Laplacian; ω fitted to the difference P₂ − T₂ must
  // explain it to rounding, and ω λ_max(D₁⁻¹A₁) must lie in [1, 2): the smoothing step damps the
  // top of the spectrum without amplifying it (4/3 exactly with an exact λ; the engine estimates
  // λ by 20 power steps).
  const int d = 3, n = 6;
  const Mesh serial = unit_box(d, n);
  const DistributedMesh part = distribute_mesh(MPI_COMM_WORLD, world_rank() == 0 ? &serial : nullptr);
  const std::vector<std::uint8_t> fixed = bottom_fixed(part);
  const RankAggregationLevels plain = rank_aggregation_levels(part, fixed, 2.5, 3, 20);
  const RankAggregationLevels smoothed = rank_aggregation_levels(part, fixed, 2.5, 3, 20, true);
  ASSERT_EQ(smoothed.global_unknowns, plain.global_unknowns);
  ASSERT_EQ(plain.interpolations.size(), 2u);
  const Matrix T2 = gathered(plain.interpolations[0]), P2 = gathered(smoothed.interpolations[0]);
  const Matrix P1 = gathered(smoothed.interpolations[1]);
  const std::vector<Eigen::Index> number = vertex_rows(part, serial.n_points());

  const Eigen::Index n_dofs = serial.n_points() * d;
  Matrix L = Matrix::Zero(n_dofs, n_dofs);
  const std::vector<VertexId> cells = serial.cells();
  for (std::size_t c = 0; c < cells.size(); c += 4)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (i != j)
          for (int k = 0; k < d; ++k) {
            const Eigen::Index a = number[cells[c + i]] * d + k, b = number[cells[c + j]] * d + k;
            L(a, b) -= 1.0;
            L(a, a) += 1.0;
          }
  const Matrix A1 = P1.transpose() * L * P1;
  Eigen::VectorXd inverse_diag = A1.diagonal();
  for (Eigen::Index i = 0; i < inverse_diag.size(); ++i) inverse_diag[i] = inverse_diag[i] > 0 ? 1.0 / inverse_diag[i] : 0.0;
  const Matrix step = inverse_diag.asDiagonal() * A1 * T2;  // D₁⁻¹ A₁ T₂
  const double omega = -(P2 - T2).cwiseProduct(step).sum() / step.squaredNorm();
  EXPECT_LT((P2 - (T2 - omega * step)).cwiseAbs().maxCoeff(), 1e-12 * P2.cwiseAbs().maxCoeff());
  // λ_max(D⁻¹A) = λ_max(D^-½ A D^-½), symmetric.
  const Eigen::VectorXd root = inverse_diag.cwiseSqrt();
  const Matrix symmetric = root.asDiagonal() * A1 * root.asDiagonal();
  const double lambda = Eigen::SelfAdjointEigenSolver<Matrix>(symmetric).eigenvalues().maxCoeff();
  if (world_rank() == 0) std::printf("second level: omega * lambda_max = %.4f\n", omega * lambda);
  EXPECT_GE(omega * lambda, 1.0);
  EXPECT_LT(omega * lambda, 2.0);
}

// Collective: CG's iterations to a relative residual of 1e-8 on A x = A x_true, with `pc`
// set up by `set_up`; the relative error of x.
template <class SetUp>
PetscInt cg_iterations(Mat A, Vec x_true, double& relative_error, SetUp&& set_up) {
  PetscHandle<KSP, KSPDestroy> cg;
  SNEDE_PETSC(KSPCreate(MPI_COMM_WORLD, cg.out()));
  SNEDE_PETSC(KSPSetOperators(cg, A, A));
  SNEDE_PETSC(KSPSetType(cg, KSPCG));
  SNEDE_PETSC(KSPSetTolerances(cg, 1e-8, 0.0, PETSC_DEFAULT, 5000));
  PC pc = nullptr;
  SNEDE_PETSC(KSPGetPC(cg, &pc));
  set_up(pc);
  VecHandle b, x;
  SNEDE_PETSC(VecDuplicate(x_true, b.out()));
  SNEDE_PETSC(VecDuplicate(x_true, x.out()));
  SNEDE_PETSC(MatMult(A, x_true, b));
  SNEDE_PETSC(KSPSolve(cg, b, x));
  KSPConvergedReason reason;
  SNEDE_PETSC(KSPGetConvergedReason(cg, &reason));
  EXPECT_GT(reason, 0) << KSPConvergedReasons[reason];
  PetscInt iterations = 0;
  SNEDE_PETSC(KSPGetIterationNumber(cg, &iterations));
  double true_norm = 0, error_norm = 0;
  SNEDE_PETSC(VecNorm(x_true, NORM_2, &true_norm));
  SNEDE_PETSC(VecAXPY(x, -1.0, x_true));
  SNEDE_PETSC(VecNorm(x, NORM_2, &error_norm));
  relative_error = error_norm / true_norm;
  return iterations;
}

// Collective: the tangent of an elastic box held at y = 0, assembled, and a right-hand side
// A x_true with x_true(row) = sin(row) + 1 (smooth and rough components alike).
struct BoxSystem {
  std::unique_ptr<ElasticBody> body;
  std::unique_ptr<DistributedAssembledTangent> tangent;
  VecHandle x_true;
};

BoxSystem box_system(const DistributedMesh& part, const std::vector<std::uint8_t>& fixed) {
  const int d = part.local->dim();
  BoxSystem system;
  system.body = std::make_unique<ElasticBody>(*part.local, LinearElastic(3e3, 0.3), 1000.0, 0.0);
  std::vector<PetscInt> rows(fixed.size());
  PetscInt n_owned_dofs = 0;
  for (VertexId v = 0; v < part.local->n_points(); ++v) {
    for (int k = 0; k < d; ++k) rows[static_cast<std::size_t>(v) * d + k] = static_cast<PetscInt>(part.global_number[v] * d + k);
    n_owned_dofs += part.owned[v] ? d : 0;
  }
  system.tangent = std::make_unique<DistributedAssembledTangent>(part, *system.body, rows, fixed, n_owned_dofs);
  system.tangent->assemble(std::vector<double>(fixed.size(), 0.0));
  SNEDE_PETSC(MatCreateVecs(system.tangent->mat(), system.x_true.out(), nullptr));
  PetscInt start = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(system.x_true, &start, &end));
  for (PetscInt row = start; row < end; ++row)
    SNEDE_PETSC(VecSetValue(system.x_true, row, std::sin(double(row)) + 1.0, INSERT_VALUES));
  SNEDE_PETSC(VecAssemblyBegin(system.x_true));
  SNEDE_PETSC(VecAssemblyEnd(system.x_true));
  return system;
}

// PCMG on `levels` with Chebyshev/Jacobi smoothing and Galerkin coarse operators.
void set_up_multigrid(PC pc, const RankAggregationLevels& levels) {
  const auto n_levels = static_cast<PetscInt>(levels.interpolations.size()) + 1;
  SNEDE_PETSC(PCSetType(pc, PCMG));
  SNEDE_PETSC(PCMGSetLevels(pc, n_levels, nullptr));
  SNEDE_PETSC(PCMGSetGalerkin(pc, PC_MG_GALERKIN_BOTH));
  for (PetscInt l = 1; l < n_levels; ++l) {
    SNEDE_PETSC(PCMGSetInterpolation(pc, l, levels.interpolations[l - 1]));
    KSP smoother = nullptr;
    PC jacobi_pc = nullptr;
    SNEDE_PETSC(PCMGGetSmoother(pc, l, &smoother));
    SNEDE_PETSC(KSPSetType(smoother, KSPCHEBYSHEV));
    SNEDE_PETSC(KSPGetPC(smoother, &jacobi_pc));
    SNEDE_PETSC(PCSetType(jacobi_pc, PCJACOBI));
  }
}

PetscInt multigrid_cg_iterations(const DistributedMesh& part, const std::vector<std::uint8_t>& fixed,
                                 const RankAggregationLevels& levels) {
  const BoxSystem system = box_system(part, fixed);
  double error = 0;
  const PetscInt iterations =
      cg_iterations(system.tangent->mat(), system.x_true, error, [&](PC pc) { set_up_multigrid(pc, levels); });
  EXPECT_LT(error, 1e-5);
  return iterations;
}

TEST(RankAggregation, MultigridCgNeedsFarFewerIterationsThanJacobiCg) {
  const DistributedMesh part = distributed_box(3, 12);
  const std::vector<std::uint8_t> fixed = bottom_fixed(part);
  const BoxSystem system = box_system(part, fixed);
  const RankAggregationLevels levels = rank_aggregation_levels(part, fixed, 2.5);
  double jacobi_error = 0, multigrid_error = 0;
  const PetscInt jacobi =
      cg_iterations(system.tangent->mat(), system.x_true, jacobi_error, [](PC pc) { SNEDE_PETSC(PCSetType(pc, PCJACOBI)); });
  const PetscInt multigrid =
      cg_iterations(system.tangent->mat(), system.x_true, multigrid_error, [&](PC pc) { set_up_multigrid(pc, levels); });
  if (world_rank() == 0) std::printf("CG iterations: Jacobi %d, multigrid %d\n", int(jacobi), int(multigrid));
  EXPECT_LT(jacobi_error, 1e-5);
  EXPECT_LT(multigrid_error, 1e-5);
  EXPECT_LT(3 * multigrid, jacobi);
}

TEST(RankAggregation, SmoothingTheLevelsSavesCgIterations) {
  const DistributedMesh part = distributed_box(3, 12);
  const std::vector<std::uint8_t> fixed = bottom_fixed(part);
  const RankAggregationLevels plain = rank_aggregation_levels(part, fixed, 2.5);
  const RankAggregationLevels smoothed = rank_aggregation_levels(part, fixed, 2.5, 0, default_direct_unknowns, true);
  const PetscInt plain_iterations = multigrid_cg_iterations(part, fixed, plain);
  const PetscInt smoothed_iterations = multigrid_cg_iterations(part, fixed, smoothed);
  if (world_rank() == 0)
    std::printf("CG iterations with multigrid: plain aggregates %d, smoothed %d\n", int(plain_iterations),
                int(smoothed_iterations));
  EXPECT_LT(smoothed_iterations, plain_iterations);
}

}  // namespace
