#include "multigrid/smoothed_aggregation.hpp"

#include <cmath>
#include <utility>

#include "core/error.hpp"

namespace snede {
namespace {

// A matrix of dim×dim blocks on the adjacency's pattern and the diagonal, in the rows of the
// adjacency's rows' dofs: block (v, u) = factor(v == u, weight of vu, degree of v) · B_v, with
// B_v the projection's block of v when one is given, else the identity.
template <class Factor>
MatHandle block_matrix(Mat adjacency, int dim, std::span<const VertexId> vertex_of_row, const VertexProjection* projection,
                       Factor factor) {
  MPI_Comm comm = MPI_COMM_NULL;
  SNEDE_PETSC(PetscObjectGetComm(reinterpret_cast<PetscObject>(adjacency), &comm));
  const int d = dim;
  PetscInt first = 0, end = 0;
  SNEDE_PETSC(MatGetOwnershipRange(adjacency, &first, &end));
  const PetscInt n_rows = end - first;
  // Preallocation from the adjacency's rows: d columns per neighbour and the diagonal.
  std::vector<PetscInt> on_rank(static_cast<std::size_t>(n_rows) * d), off_rank(on_rank.size());
  for (PetscInt row = first; row < end; ++row) {
    PetscInt n = 0;
    const PetscInt* columns = nullptr;
    SNEDE_PETSC(MatGetRow(adjacency, row, &n, &columns, nullptr));
    PetscInt inside = 1;  // the diagonal
    for (PetscInt k = 0; k < n; ++k) inside += columns[k] >= first && columns[k] < end && columns[k] != row;
    const PetscInt outside = n + 1 - inside;
    SNEDE_PETSC(MatRestoreRow(adjacency, row, &n, &columns, nullptr));  // which zeroes n
    for (int k = 0; k < d; ++k) {
      on_rank[static_cast<std::size_t>(row - first) * d + k] = inside * d;
      off_rank[static_cast<std::size_t>(row - first) * d + k] = outside * d;
    }
  }
  MatHandle matrix;
  SNEDE_PETSC(MatCreateAIJ(comm, n_rows * d, n_rows * d, PETSC_DETERMINE, PETSC_DETERMINE, 0, on_rank.data(), 0,
                           off_rank.data(), matrix.out()));
  std::vector<double> B(static_cast<std::size_t>(d) * d, 0.0), block(B.size());
  for (int k = 0; k < d; ++k) B[static_cast<std::size_t>(k) * d + k] = 1.0;
  std::vector<PetscInt> rows(d), block_columns(d);
  for (PetscInt row = first; row < end; ++row) {
    if (projection) (*projection)(vertex_of_row[static_cast<std::size_t>(row - first)], B);
    PetscInt n = 0;
    const PetscInt* columns = nullptr;
    const PetscScalar* weights = nullptr;
    SNEDE_PETSC(MatGetRow(adjacency, row, &n, &columns, &weights));
    double degree = 0;
    for (PetscInt k = 0; k < n; ++k) degree += columns[k] != row ? PetscRealPart(weights[k]) : 0.0;
    const auto put = [&](PetscInt column, double scale) {
      for (int i = 0; i < d * d; ++i) block[static_cast<std::size_t>(i)] = scale * B[static_cast<std::size_t>(i)];
      for (int k = 0; k < d; ++k) rows[k] = row * d + k, block_columns[k] = column * d + k;
      SNEDE_PETSC(MatSetValues(matrix, d, rows.data(), d, block_columns.data(), block.data(), INSERT_VALUES));
    };
    for (PetscInt k = 0; k < n; ++k)
      if (columns[k] != row) put(columns[k], factor(false, PetscRealPart(weights[k]), degree));
    put(row, factor(true, 0.0, degree));
    SNEDE_PETSC(MatRestoreRow(adjacency, row, &n, &columns, &weights));
  }
  SNEDE_PETSC(MatAssemblyBegin(matrix, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(matrix, MAT_FINAL_ASSEMBLY));
  return matrix;
}

// The inverse of A's diagonal, 0 where the diagonal is 0 (an unknown no operator row reaches).
VecHandle inverse_diagonal(Mat A) {
  VecHandle inverse;
  SNEDE_PETSC(MatCreateVecs(A, inverse.out(), nullptr));
  SNEDE_PETSC(MatGetDiagonal(A, inverse));
  PetscScalar* values = nullptr;
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(inverse, &n));
  SNEDE_PETSC(VecGetArray(inverse, &values));
  for (PetscInt i = 0; i < n; ++i) values[i] = PetscRealPart(values[i]) > 0 ? 1.0 / values[i] : 0.0;
  SNEDE_PETSC(VecRestoreArray(inverse, &values));
  return inverse;
}

// λ_max of D⁻¹A by power iteration from a start vector that depends only on the row's number
// (not on the rank count or a random state). The estimate approaches from below: ω comes out a
// little larger than the bound's, which only sharpens the smoothing of the top modes.
double largest_eigenvalue(Mat A, Vec inverse_diag) {
  constexpr int iterations = 20;
  VecHandle x, y;
  SNEDE_PETSC(MatCreateVecs(A, x.out(), y.out()));
  PetscInt first = 0, end = 0;
  SNEDE_PETSC(VecGetOwnershipRange(x, &first, &end));
  PetscScalar* values = nullptr;
  SNEDE_PETSC(VecGetArray(x, &values));
  for (PetscInt i = first; i < end; ++i) values[i - first] = 1.0 + static_cast<double>(i % 7) / 7.0;
  SNEDE_PETSC(VecRestoreArray(x, &values));
  double lambda = 0;
  for (int k = 0; k < iterations; ++k) {
    PetscReal before = 0;
    SNEDE_PETSC(VecNorm(x, NORM_2, &before));
    if (before == 0) return 0;
    SNEDE_PETSC(VecScale(x, 1.0 / before));
    SNEDE_PETSC(MatMult(A, x, y));
    SNEDE_PETSC(VecPointwiseMult(y, y, inverse_diag));
    PetscReal after = 0;
    SNEDE_PETSC(VecNorm(y, NORM_2, &after));
    lambda = after;
    SNEDE_PETSC(VecSwap(x, y));
  }
  return lambda;
}

// P_{l+1} = (I − ω D⁻¹ A_l) T_{l+1} for l ≥ 1, from A₁ (`level_operator`).
void smooth_coarse_interpolations(MatHandle level_operator, std::span<AggregateLevel> finest_first) {
  for (std::size_t l = 1; l < finest_first.size(); ++l) {
    const VecHandle inverse_diag = inverse_diagonal(level_operator);
    const double lambda = largest_eigenvalue(level_operator, inverse_diag);
    MatHandle& tentative = finest_first[l].interpolation;
    if (lambda > 0 && std::isfinite(lambda)) {
      MatHandle smoothed;  // T − ω D⁻¹ A T
      SNEDE_PETSC(MatMatMult(level_operator, tentative, MAT_INITIAL_MATRIX, PETSC_DEFAULT, smoothed.out()));
      SNEDE_PETSC(MatDiagonalScale(smoothed, inverse_diag, nullptr));
      SNEDE_PETSC(MatAYPX(smoothed, -4.0 / (3.0 * lambda), tentative, DIFFERENT_NONZERO_PATTERN));
      tentative = std::move(smoothed);
    }
    if (l + 1 < finest_first.size()) {
      MatHandle coarser;
      SNEDE_PETSC(MatPtAP(level_operator, tentative, MAT_INITIAL_MATRIX, PETSC_DEFAULT, coarser.out()));
      level_operator = std::move(coarser);
    }
  }
}

}  // namespace

MatHandle cell_edge_adjacency(MPI_Comm comm, const Mesh& mesh, std::span<const std::int64_t> row_of_vertex,
                              PetscInt n_rows) {
  const int corners = mesh.cell_dim() + 1;
  const std::vector<VertexId> cells = mesh.cells();
  MatHandle adjacency;
  // A vertex of a tetrahedral mesh has a few tens of neighbours; PETSc grows a row that needs
  // more (rare: a vertex shared by many cells), at some cost, rather than failing.
  SNEDE_PETSC(MatCreateAIJ(comm, n_rows, n_rows, PETSC_DETERMINE, PETSC_DETERMINE, 32, nullptr, 16, nullptr,
                           adjacency.out()));
  SNEDE_PETSC(MatSetOption(adjacency, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  const PetscScalar one = 1.0;
  for (std::size_t c = 0; c < cells.size(); c += static_cast<std::size_t>(corners))
    for (int i = 0; i < corners; ++i)
      for (int j = 0; j < corners; ++j)
        if (i != j) {
          const auto a = static_cast<PetscInt>(row_of_vertex[static_cast<std::size_t>(cells[c + i])]);
          const auto b = static_cast<PetscInt>(row_of_vertex[static_cast<std::size_t>(cells[c + j])]);
          SNEDE_PETSC(MatSetValues(adjacency, 1, &a, 1, &b, &one, ADD_VALUES));
        }
  SNEDE_PETSC(MatAssemblyBegin(adjacency, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(adjacency, MAT_FINAL_ASSEMBLY));
  return adjacency;
}

void smooth_interpolations(Mat adjacency, int dim, std::span<const VertexId> vertex_of_row,
                           const VertexProjection& projection, std::span<AggregateLevel> finest_first,
                           bool coarse_levels_too) {
  if (finest_first.empty()) return;
  constexpr double omega = 2.0 / 3.0;
  // Π (I − ω D⁻¹ L); a row with no neighbour keeps Π's block.
  const MatHandle S = block_matrix(adjacency, dim, vertex_of_row, &projection, [&](bool diagonal, double weight, double degree) {
    if (diagonal) return degree > 0 ? 1.0 - omega : 1.0;
    return degree > 0 ? omega * weight / degree : 0.0;
  });
  MatHandle smoothed;
  SNEDE_PETSC(MatMatMult(S, finest_first[0].interpolation, MAT_INITIAL_MATRIX, PETSC_DEFAULT, smoothed.out()));
  finest_first[0].interpolation = std::move(smoothed);
  if (!coarse_levels_too || finest_first.size() < 2) return;
  // L ⊗ I, unprojected: the smoothed interpolation's columns are projected already (Π P = P).
  const MatHandle laplacian = block_matrix(adjacency, dim, vertex_of_row, nullptr, [](bool diagonal, double weight, double degree) {
    return diagonal ? degree : -weight;
  });
  MatHandle first_coarse_operator;
  SNEDE_PETSC(MatPtAP(laplacian, finest_first[0].interpolation, MAT_INITIAL_MATRIX, PETSC_DEFAULT,
                      first_coarse_operator.out()));
  smooth_coarse_interpolations(std::move(first_coarse_operator), finest_first);
}

}  // namespace snede
