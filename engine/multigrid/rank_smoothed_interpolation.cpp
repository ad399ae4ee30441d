#include "multigrid/rank_smoothed_interpolation.hpp"

#include <algorithm>
#include <vector>

#include "core/error.hpp"

namespace snede {
namespace {

// The vertex graph's adjacency over every rank's cells, one row per vertex in PETSc's vertex
// numbering (MPIAIJ, the owned vertices' rows on each rank): entry (a, b) the number of cells
// that have the edge ab.
MatHandle cell_edge_adjacency(const DistributedMesh& part, PetscInt n_owned) {
  const Mesh& mesh = *part.local;
  const int corners = mesh.cell_dim() + 1;
  const std::vector<VertexId> cells = mesh.cells();
  MatHandle adjacency;
  SNEDE_PETSC(MatCreate(part.comm, adjacency.out()));
  SNEDE_PETSC(MatSetSizes(adjacency, n_owned, n_owned, PETSC_DETERMINE, PETSC_DETERMINE));
  SNEDE_PETSC(MatSetType(adjacency, MATMPIAIJ));
  // A vertex of a tetrahedral mesh has a few tens of neighbours; PETSc grows a row that needs
  // more (rare: a vertex shared by many cells), at some cost, rather than failing.
  SNEDE_PETSC(MatMPIAIJSetPreallocation(adjacency, 32, nullptr, 16, nullptr));
  SNEDE_PETSC(MatSetOption(adjacency, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  const PetscScalar one = 1.0;
  for (std::size_t c = 0; c < cells.size(); c += static_cast<std::size_t>(corners))
    for (int i = 0; i < corners; ++i)
      for (int j = 0; j < corners; ++j)
        if (i != j) {
          const auto a = static_cast<PetscInt>(part.global_number[static_cast<std::size_t>(cells[c + i])]);
          const auto b = static_cast<PetscInt>(part.global_number[static_cast<std::size_t>(cells[c + j])]);
          SNEDE_PETSC(MatSetValues(adjacency, 1, &a, 1, &b, &one, ADD_VALUES));
        }
  SNEDE_PETSC(MatAssemblyBegin(adjacency, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(adjacency, MAT_FINAL_ASSEMBLY));
  return adjacency;
}

}  // namespace

MatHandle rank_smoothed_interpolation(const DistributedMesh& part, const VertexProjection& projection, Mat tentative) {
  constexpr double omega = 2.0 / 3.0;
  const int d = part.local->dim();
  std::vector<std::size_t> owned_local;  // the owned vertices' local ids, in their rows' order
  for (std::size_t v = 0; v < part.owned.size(); ++v)
    if (part.owned[v]) owned_local.push_back(v);
  std::sort(owned_local.begin(), owned_local.end(),
            [&](std::size_t a, std::size_t b) { return part.global_number[a] < part.global_number[b]; });
  const auto n_owned = static_cast<PetscInt>(owned_local.size());
  const MatHandle adjacency = cell_edge_adjacency(part, n_owned);
  PetscInt first = 0, end = 0;
  SNEDE_PETSC(MatGetOwnershipRange(adjacency, &first, &end));

  // Preallocation of S from the adjacency's rows: d columns per neighbour and the diagonal.
  std::vector<PetscInt> on_rank(static_cast<std::size_t>(n_owned) * d), off_rank(on_rank.size());
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
  MatHandle S;
  SNEDE_PETSC(MatCreateAIJ(part.comm, n_owned * d, n_owned * d, PETSC_DETERMINE, PETSC_DETERMINE, 0, on_rank.data(), 0,
                           off_rank.data(), S.out()));
  std::vector<double> P(static_cast<std::size_t>(d) * d), block(P.size());
  std::vector<PetscInt> rows(d), block_columns(d);
  for (PetscInt row = first; row < end; ++row) {
    projection(static_cast<VertexId>(owned_local[static_cast<std::size_t>(row - first)]), P);
    PetscInt n = 0;
    const PetscInt* columns = nullptr;
    const PetscScalar* weights = nullptr;
    SNEDE_PETSC(MatGetRow(adjacency, row, &n, &columns, &weights));
    double degree = 0;
    for (PetscInt k = 0; k < n; ++k) degree += columns[k] != row ? PetscRealPart(weights[k]) : 0.0;
    const auto put = [&](PetscInt column, double factor) {
      for (int i = 0; i < d * d; ++i) block[static_cast<std::size_t>(i)] = factor * P[static_cast<std::size_t>(i)];
      for (int k = 0; k < d; ++k) rows[k] = row * d + k, block_columns[k] = column * d + k;
      SNEDE_PETSC(MatSetValues(S, d, rows.data(), d, block_columns.data(), block.data(), INSERT_VALUES));
    };
    for (PetscInt k = 0; k < n; ++k)
      if (columns[k] != row) put(columns[k], degree > 0 ? omega * PetscRealPart(weights[k]) / degree : 0.0);
    put(row, degree > 0 ? 1.0 - omega : 1.0);
    SNEDE_PETSC(MatRestoreRow(adjacency, row, &n, &columns, &weights));
  }
  SNEDE_PETSC(MatAssemblyBegin(S, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(S, MAT_FINAL_ASSEMBLY));
  MatHandle smoothed;
  SNEDE_PETSC(MatMatMult(S, tentative, MAT_INITIAL_MATRIX, PETSC_DEFAULT, smoothed.out()));
  return smoothed;
}

}  // namespace snede
