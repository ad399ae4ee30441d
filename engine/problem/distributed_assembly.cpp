#include "problem/distributed_assembly.hpp"

#include <algorithm>
#include <initializer_list>
#include <limits>
#include <memory>
#include <type_traits>
#include <unordered_map>

#include "core/csr_matrix.hpp"
#include "core/rank_messages.hpp"
#include "core/error.hpp"
#include "problem/projected_stiffness.hpp"
#include "problem/vertex_neighbours.hpp"

namespace snede {
namespace {

// P's blocks when whole dofs are fixed: diagonal, 0 on a fixed dof and 1 on a free one.
std::vector<double> diagonal_projection(std::span<const std::uint8_t> fixed_local, int dim) {
  std::vector<double> blocks(fixed_local.size() * static_cast<std::size_t>(dim));
  for (std::size_t dof = 0; dof < fixed_local.size(); ++dof)
    blocks[dof * dim + dof % dim] = fixed_local[dof] ? 0.0 : 1.0;
  return blocks;
}

// The diagonal and off-diagonal SeqAIJ parts of this rank's rows (one rank: the matrix itself, no
// off-diagonal part), and the global column of each off-diagonal part column.
struct RankParts {
  Mat diagonal = nullptr, off_diagonal = nullptr;
  const PetscInt* off_diagonal_column = nullptr;
};

RankParts rank_parts(Mat A) {
  PetscBool is_mpi = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATMPIAIJ, &is_mpi));
  RankParts parts;
  if (!is_mpi) {
    parts.diagonal = A;
    return parts;
  }
  SNEDE_PETSC(MatMPIAIJGetSeqAIJ(A, &parts.diagonal, &parts.off_diagonal, &parts.off_diagonal_column));
  return parts;
}

}  // namespace

DistributedAssembledTangent::DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body,
                                                         std::span<const PetscInt> local_rows,
                                                         std::span<const std::uint8_t> fixed_local, PetscInt n_owned_dofs,
                                                         double constraint_stiffness)
    : DistributedAssembledTangent(part, body, local_rows, diagonal_projection(fixed_local, part.local->dim()),
                                  n_owned_dofs, constraint_stiffness) {}

DistributedAssembledTangent::DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body,
                                                         std::span<const PetscInt> local_rows,
                                                         std::span<const double> projection, PetscInt n_owned_dofs,
                                                         double constraint_stiffness)
    : part_(part), body_(body), dim_(part.local->dim()), corners_(part.local->cell_dim() + 1),
      local_rows_(local_rows.begin(), local_rows.end()), projection_(projection.begin(), projection.end()),
      complement_(complement_blocks(projection_, part.local->dim())) {
  for (double& x : complement_) x *= constraint_stiffness;
  const PetscInt n_owned_blocks = n_owned_dofs / dim_;
  MPI_Exscan(&n_owned_blocks, &first_block_, 1, MPIU_INT, MPI_SUM, part.comm);
  int rank = 0;
  MPI_Comm_rank(part.comm, &rank);
  if (rank == 0) first_block_ = 0;  // MPI_Exscan leaves rank 0's undefined
  find_neighbours();
  make_matrix(n_owned_dofs);
  find_slots();

  // The rigid-body motions from the owned vertices' reference coordinates.
  VecHandle coordinates;
  SNEDE_PETSC(VecCreateMPI(part.comm, n_owned_dofs, PETSC_DETERMINE, coordinates.out()));
  SNEDE_PETSC(VecSetBlockSize(coordinates, dim_));
  const std::vector<double>& points = part.local->points();
  for (std::size_t v = 0; v < part.owned.size(); ++v)
    if (part.owned[v])
      SNEDE_PETSC(VecSetValues(coordinates, dim_, &local_rows_[v * dim_], &points[v * dim_], INSERT_VALUES));
  SNEDE_PETSC(VecAssemblyBegin(coordinates));
  SNEDE_PETSC(VecAssemblyEnd(coordinates));
  MatNullSpace rigid = nullptr;
  SNEDE_PETSC(MatNullSpaceCreateRigidBody(coordinates, &rigid));
  const PetscErrorCode set = MatSetNearNullSpace(A_, rigid);
  MatNullSpaceDestroy(&rigid);
  SNEDE_PETSC(set);
}

void DistributedAssembledTangent::find_neighbours() {
  // Sorted by global number, so that a row's columns come in PETSc's order.
  VertexNeighbours found = vertex_neighbours(part_.local->connectivity(), static_cast<VertexId>(part_.owned.size()),
                                             corners_, false, part_.global_number);
  neighbour_start_ = std::move(found.start);
  neighbours_ = std::move(found.neighbours);
  block_rank_ = std::move(found.block_rank);
  self_rank_ = std::move(found.self_rank);
}

void DistributedAssembledTangent::make_matrix(PetscInt n_owned_dofs) {
  const MPI_Comm comm = part_.comm;
  int size = 1;
  MPI_Comm_size(comm, &size);
  const PetscInt n_owned_blocks = n_owned_dofs / dim_;
  std::vector<PetscInt> first_blocks(static_cast<std::size_t>(size) + 1);
  MPI_Allgather(&first_block_, 1, MPIU_INT, first_blocks.data(), 1, MPIU_INT, comm);
  first_blocks[size] = std::numeric_limits<PetscInt>::max();
  const std::vector<std::int64_t>& number = part_.global_number;
  auto columns_of = [&](std::size_t v, auto&& add) {
    for (std::size_t k = neighbour_start_[v]; k < neighbour_start_[v + 1]; ++k) add(static_cast<PetscInt>(number[neighbours_[k]]));
  };
  // A ghost's row, to its owner: [its number, how many columns, the columns' numbers].
  std::vector<std::vector<PetscInt>> outgoing(size);
  for (std::size_t v = 0; v < part_.owned.size(); ++v) {
    if (part_.owned[v]) continue;
    const auto g = static_cast<PetscInt>(number[v]);
    const auto owner = std::upper_bound(first_blocks.begin(), first_blocks.end(), g) - first_blocks.begin() - 1;
    std::vector<PetscInt>& message = outgoing[owner];
    message.push_back(g);
    message.push_back(static_cast<PetscInt>(neighbour_start_[v + 1] - neighbour_start_[v]));
    columns_of(v, [&](PetscInt column) { message.push_back(column); });
  }
  const std::vector<PetscInt> received = exchange_messages(comm, outgoing, MPIU_INT);
  // The columns other ranks' cells give an owned row, by the row's global number.
  std::unordered_map<PetscInt, std::vector<PetscInt>> extra;
  for (std::size_t at = 0; at < received.size();) {
    std::vector<PetscInt>& columns = extra[received[at]];
    const auto count = static_cast<std::size_t>(received[at + 1]);
    columns.insert(columns.end(), received.begin() + static_cast<std::ptrdiff_t>(at + 2),
                   received.begin() + static_cast<std::ptrdiff_t>(at + 2 + count));
    at += 2 + count;
  }
  // Each owned row's block columns: its star's and the others', once each, sorted.
  std::vector<std::size_t> owned_vertex(static_cast<std::size_t>(n_owned_blocks));
  std::vector<std::vector<PetscInt>> row_columns(static_cast<std::size_t>(n_owned_blocks));
  std::vector<PetscInt> diagonal_blocks(static_cast<std::size_t>(n_owned_blocks)),
      off_diagonal_blocks(static_cast<std::size_t>(n_owned_blocks));
  for (std::size_t v = 0; v < part_.owned.size(); ++v) {
    if (!part_.owned[v]) continue;
    const auto g = static_cast<PetscInt>(number[v]);
    std::vector<PetscInt>& columns = row_columns[g - first_block_];
    columns_of(v, [&](PetscInt column) { columns.push_back(column); });
    if (const auto found = extra.find(g); found != extra.end()) {
      columns.insert(columns.end(), found->second.begin(), found->second.end());
      std::sort(columns.begin(), columns.end());
      columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
    }
    for (PetscInt column : columns)
      ++(column >= first_block_ && column < first_block_ + n_owned_blocks ? diagonal_blocks : off_diagonal_blocks)[g - first_block_];
  }
  SNEDE_PETSC(MatCreate(comm, A_.out()));
  SNEDE_PETSC(MatSetType(A_, MATAIJ));
  SNEDE_PETSC(MatSetSizes(A_, n_owned_dofs, n_owned_dofs, PETSC_DETERMINE, PETSC_DETERMINE));
  SNEDE_PETSC(MatSetBlockSize(A_, dim_));
  SNEDE_PETSC(MatXAIJSetPreallocation(A_, dim_, diagonal_blocks.data(), off_diagonal_blocks.data(), nullptr, nullptr));
  // The structure, row by row in column order (PETSc's fast path), every value zero.
  std::vector<PetscInt> scalar_columns;
  std::vector<double> zeros;
  for (PetscInt b = 0; b < n_owned_blocks; ++b) {
    scalar_columns.clear();
    for (PetscInt column : row_columns[b])
      for (int j = 0; j < dim_; ++j) scalar_columns.push_back(column * dim_ + j);
    zeros.assign(scalar_columns.size(), 0.0);
    for (int i = 0; i < dim_; ++i) {
      const PetscInt row = (first_block_ + b) * dim_ + i;
      SNEDE_PETSC(MatSetValues(A_, 1, &row, static_cast<PetscInt>(scalar_columns.size()), scalar_columns.data(),
                               zeros.data(), INSERT_VALUES));
    }
    std::vector<PetscInt>().swap(row_columns[b]);
  }
  SNEDE_PETSC(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatSetOption(A_, MAT_SYMMETRIC, PETSC_TRUE));
  SNEDE_PETSC(MatSetOption(A_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
}

void DistributedAssembledTangent::find_slots() {
  const RankParts parts = rank_parts(A_);
  const CsrView diagonal(parts.diagonal);
  std::unique_ptr<CsrView> off_diagonal;
  if (parts.off_diagonal) off_diagonal = std::make_unique<CsrView>(parts.off_diagonal);
  const std::vector<std::int64_t>& number = part_.global_number;
  slot_.assign(neighbours_.size(), 0);
  std::int32_t ghost_blocks = 0;
  for (std::size_t v = 0; v < part_.owned.size(); ++v) {
    const std::size_t row = part_.owned[v] ? static_cast<std::size_t>((number[v] - first_block_) * dim_) : 0;
    for (std::size_t k = neighbour_start_[v]; k < neighbour_start_[v + 1]; ++k) {
      if (!part_.owned[v]) {
        slot_[k] = ghost_blocks++;
        continue;
      }
      const auto g = static_cast<PetscInt>(number[neighbours_[k]]);
      const PetscInt local_column = (g - first_block_) * dim_;
      const bool in_diagonal = parts.off_diagonal == nullptr || (local_column >= 0 && local_column < diagonal.rows);
      const CsrView& view = in_diagonal ? diagonal : *off_diagonal;
      const PetscInt* begin = view.column + view.start[row];
      const PetscInt* end = view.column + view.start[row + 1];
      const PetscInt* found =
          in_diagonal ? std::lower_bound(begin, end, local_column)
                      : std::lower_bound(begin, end, g * dim_, [&](PetscInt column, PetscInt global) {
                          return parts.off_diagonal_column[column] < global;
                        });
      const PetscInt wanted = in_diagonal ? local_column : g * dim_;
      if (found == end || (in_diagonal ? *found : parts.off_diagonal_column[*found]) != wanted)
        throw std::logic_error("the assembled tangent lacks a block of its own cells");
      const auto offset = static_cast<std::int32_t>(found - begin);
      slot_[k] = in_diagonal ? offset : -1 - offset;
    }
  }
  ghost_values_.assign(static_cast<std::size_t>(ghost_blocks) * dim_ * dim_, 0.0);
}

void DistributedAssembledTangent::assemble(std::span<const double> u) {
  {
    const RankParts parts = rank_parts(A_);
    const CsrView diagonal(parts.diagonal);  // given back before assembling
    std::unique_ptr<CsrView> off_diagonal;
    if (parts.off_diagonal) off_diagonal = std::make_unique<CsrView>(parts.off_diagonal);
    for (const CsrView* view : std::initializer_list<const CsrView*>{&diagonal, off_diagonal.get()})
      if (view) std::fill(view->value, view->value + view->start[view->rows], 0.0);
    std::fill(ghost_values_.begin(), ghost_values_.end(), 0.0);
    const bool membrane = part_.local->is_surface();
    MembranePositivePart positive_part;
    const std::vector<std::int64_t>& number = part_.global_number;
    auto add_all = [&](auto dimension) {
      constexpr int D = decltype(dimension)::value;
      // Adds the D × D block at K (rows `stride` apart) at vertex v's k-th neighbours_ entry.
      auto add_block = [&](std::size_t v, std::size_t k, const double* K, std::size_t stride) {
        if (!part_.owned[v]) {
          double* block = ghost_values_.data() + static_cast<std::size_t>(slot_[k]) * D * D;
          for (int i = 0; i < D; ++i)
            for (int j = 0; j < D; ++j) block[i * D + j] += K[i * stride + j];
          return;
        }
        const std::size_t row = static_cast<std::size_t>((number[v] - first_block_) * D);
        const CsrView& view = slot_[k] >= 0 ? diagonal : *off_diagonal;
        const std::size_t offset = static_cast<std::size_t>(slot_[k] >= 0 ? slot_[k] : -1 - slot_[k]);
        for (int i = 0; i < D; ++i) {
          PetscScalar* entries = view.value + view.start[row + i] + offset;
          for (int j = 0; j < D; ++j) entries[j] += K[i * stride + j];
        }
      };
      for_each_projected_element_matrix(body_, u, projection_, [&](ElementId e, std::span<const VertexId> vertices,
                                                                  std::span<const double> element_matrix) {
        const std::span<const double> K = membrane ? positive_part(element_matrix) : element_matrix;
        const std::size_t n = vertices.size() * D;
        const std::int32_t* ranks = block_rank_.data() + static_cast<std::size_t>(e) * corners_ * corners_;
        for (int a = 0; a < corners_; ++a)
          for (int b = 0; b < corners_; ++b)
            add_block(vertices[a], neighbour_start_[vertices[a]] + ranks[a * corners_ + b], K.data() + (a * n + b) * D, n);
      });
      // + c (I − P) on every owned vertex's diagonal block (zero for a free one), as in the shell.
      for (std::size_t v = 0; v < part_.owned.size(); ++v)
        if (part_.owned[v]) add_block(v, neighbour_start_[v] + self_rank_[v], complement_.data() + v * D * D, D);
    };
    if (dim_ == 3) {
      add_all(std::integral_constant<int, 3>{});
    } else {
      add_all(std::integral_constant<int, 2>{});
    }
  }
  add_ghost_rows();
  SNEDE_PETSC(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY));
}

void DistributedAssembledTangent::add_ghost_rows() {
  const std::vector<std::int64_t>& number = part_.global_number;
  std::vector<PetscInt> columns;
  std::vector<double> values;
  for (std::size_t v = 0; v < part_.owned.size(); ++v) {
    if (part_.owned[v]) continue;
    const std::size_t first = neighbour_start_[v], count = neighbour_start_[v + 1] - first;
    columns.clear();
    for (std::size_t k = first; k < first + count; ++k)
      for (int j = 0; j < dim_; ++j) columns.push_back(static_cast<PetscInt>(number[neighbours_[k]] * dim_ + j));
    for (int i = 0; i < dim_; ++i) {
      values.clear();
      for (std::size_t k = first; k < first + count; ++k)
        for (int j = 0; j < dim_; ++j)
          values.push_back(ghost_values_[(static_cast<std::size_t>(slot_[k]) * dim_ + i) * dim_ + j]);
      const auto row = static_cast<PetscInt>(number[v] * dim_ + i);
      SNEDE_PETSC(MatSetValues(A_, 1, &row, static_cast<PetscInt>(columns.size()), columns.data(), values.data(),
                               ADD_VALUES));
    }
  }
}

}  // namespace snede
