// The Galerkin product by vertex blocks (galerkin_product.hpp) against PETSc's MatPtAP on the
// same matrices: a random symmetric BAIJ matrix over a random vertex graph (an AIJ copy for
// PETSc, whose product takes no BAIJ), and a random block interpolation whose copies have 1 to
// dim columns (a constrained copy has fewer; half the others' blocks a weight times the
// identity, as a free vertex's), turned into the scalar AIJ interpolation PETSc multiplies
// with. Also after new values in A (recompute keeps the structure), in 2D and 3D; and an AIJ A
// is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "multigrid/galerkin_product.hpp"

using namespace snede;

namespace {

struct Problem {
  int d;
  PetscInt n_vertices;
  std::vector<std::set<PetscInt>> neighbours;  // symmetric, itself included
  MatHandle A, A_aij, P;  // A in blocks of d × d, and the same values in AIJ
  BlockInterpolation blocks;
};

// A with a d × d block for every pair of neighbours (AssembledTangent's BAIJ layout); symmetric
// values drawn from `random`; then its AIJ copy.
void fill_A(Problem& problem, std::mt19937& random) {
  const int d = problem.d;
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<PetscInt> block_start{0}, block_columns;
  for (PetscInt v = 0; v < problem.n_vertices; ++v) {
    block_columns.insert(block_columns.end(), problem.neighbours[v].begin(), problem.neighbours[v].end());
    block_start.push_back(static_cast<PetscInt>(block_columns.size()));
  }
  const PetscInt rows = problem.n_vertices * d;
  if (!problem.A) {
    SNEDE_PETSC(MatCreate(PETSC_COMM_SELF, problem.A.out()));
    SNEDE_PETSC(MatSetSizes(problem.A, rows, rows, rows, rows));
    SNEDE_PETSC(MatSetType(problem.A, MATSEQBAIJ));
    SNEDE_PETSC(MatSeqBAIJSetPreallocationCSR(problem.A, d, block_start.data(), block_columns.data(), nullptr));
  }
  for (PetscInt v = 0; v < problem.n_vertices; ++v)
    for (PetscInt w : problem.neighbours[v])
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) {
          const PetscInt r = v * d + i, c = w * d + j;
          if (c < r) continue;
          const double x = value(random) + (c == r ? 10.0 : 0.0);
          SNEDE_PETSC(MatSetValue(problem.A, r, c, x, INSERT_VALUES));
          SNEDE_PETSC(MatSetValue(problem.A, c, r, x, INSERT_VALUES));
        }
  SNEDE_PETSC(MatAssemblyBegin(problem.A, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(problem.A, MAT_FINAL_ASSEMBLY));
  if (problem.A_aij) {
    SNEDE_PETSC(MatConvert(problem.A, MATSEQAIJ, MAT_REUSE_MATRIX, problem.A_aij.slot()));
  } else {
    SNEDE_PETSC(MatConvert(problem.A, MATSEQAIJ, MAT_INITIAL_MATRIX, problem.A_aij.out()));
  }
}

Problem random_problem(int d, std::mt19937& random) {
  Problem problem{d, 60, {}, {}, {}, {}, {}};
  problem.neighbours.resize(problem.n_vertices);
  std::uniform_int_distribution<PetscInt> vertex(0, problem.n_vertices - 1);
  for (PetscInt v = 0; v < problem.n_vertices; ++v) {
    problem.neighbours[v].insert(v);
    for (int k = 0; k < 4; ++k) {
      const PetscInt w = vertex(random);
      problem.neighbours[v].insert(w);
      problem.neighbours[w].insert(v);
    }
  }
  fill_A(problem, random);
  // 14 copies with 1..d columns; each vertex in up to 3 of them.
  const PetscInt copies = 14;
  std::uniform_int_distribution<int> columns(1, d), count(0, 3);
  std::uniform_int_distribution<PetscInt> copy(0, copies - 1);
  std::uniform_real_distribution<double> weight(-1.0, 1.0);
  std::bernoulli_distribution coin(0.5);
  BlockInterpolation& b = problem.blocks;
  b.dim = d;
  b.first_column.assign(1, 0);
  for (PetscInt c = 0; c < copies; ++c) b.first_column.push_back(b.first_column.back() + columns(random));
  b.start.assign(1, 0);
  for (PetscInt v = 0; v < problem.n_vertices; ++v) {
    std::set<PetscInt> mine;
    for (int k = count(random); k > 0; --k) mine.insert(copy(random));
    for (PetscInt c : mine) {
      b.copy.push_back(c);
      // Half the blocks of copies with d columns are a weight times the identity (a free vertex).
      const bool identity_times = b.columns(c) == d && coin(random);
      const double s = weight(random);
      for (int i = 0; i < d; ++i)
        for (int p = 0; p < d; ++p)
          b.block.push_back(identity_times ? (i == p ? s : 0.0) : p < b.columns(c) ? weight(random) : 0.0);
    }
    b.start.push_back(b.copy.size());
  }
  // The same interpolation as a scalar AIJ matrix.
  const PetscInt rows = problem.n_vertices * d, unknowns = b.first_column.back();
  SNEDE_PETSC(MatCreateSeqAIJ(PETSC_COMM_SELF, rows, unknowns, 3 * d, nullptr, problem.P.out()));
  for (PetscInt v = 0; v < problem.n_vertices; ++v)
    for (std::size_t t = b.start[v]; t < b.start[v + 1]; ++t)
      for (int i = 0; i < d; ++i)
        for (PetscInt p = 0; p < b.columns(b.copy[t]); ++p)
          SNEDE_PETSC(MatSetValue(problem.P, v * d + i, b.first_column[b.copy[t]] + p, b.block[t * d * d + i * d + p],
                                  INSERT_VALUES));
  SNEDE_PETSC(MatAssemblyBegin(problem.P, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(problem.P, MAT_FINAL_ASSEMBLY));
  return problem;
}

// The largest difference between two square matrices' entries, over the largest entry.
double relative_difference(Mat X, Mat Y) {
  PetscInt n = 0;
  SNEDE_PETSC(MatGetSize(X, &n, nullptr));
  double largest = 0, difference = 0;
  for (PetscInt r = 0; r < n; ++r)
    for (PetscInt c = 0; c < n; ++c) {
      PetscScalar x = 0, y = 0;
      SNEDE_PETSC(MatGetValues(X, 1, &r, 1, &c, &x));
      SNEDE_PETSC(MatGetValues(Y, 1, &r, 1, &c, &y));
      largest = std::max(largest, std::abs(y));
      difference = std::max(difference, std::abs(x - y));
    }
  return difference / largest;
}

}  // namespace

class BlockGalerkinProduct : public ::testing::TestWithParam<int> {};

TEST_P(BlockGalerkinProduct, EqualsPetscsProductBeforeAndAfterNewValues) {
  std::mt19937 random(7 + GetParam());
  Problem problem = random_problem(GetParam(), random);
  const auto blocks = block_galerkin_product(problem.A, problem.blocks);
  const auto reference = petsc_galerkin_product(problem.A_aij, problem.P);
  EXPECT_LT(relative_difference(blocks->matrix(), reference->matrix()), 1e-14);
  fill_A(problem, random);
  blocks->recompute();
  reference->recompute();
  EXPECT_LT(relative_difference(blocks->matrix(), reference->matrix()), 1e-14);
}

TEST_P(BlockGalerkinProduct, RefusesAnAijMatrix) {
  std::mt19937 random(11 + GetParam());
  const Problem problem = random_problem(GetParam(), random);
  EXPECT_THROW(block_galerkin_product(problem.A_aij, problem.blocks), std::logic_error);
}

INSTANTIATE_TEST_SUITE_P(Dimensions, BlockGalerkinProduct, ::testing::Values(2, 3));
