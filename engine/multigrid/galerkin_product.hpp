// Galerkin coarse operators Pᵀ A P of multigrid levels (multigrid.hpp). Two ways to compute one:
// PETSc's sparse product (AIJ matrices), and snede's own for an interpolation given vertex by
// vertex in dim × dim blocks (the grid levels, grid_multigrid.hpp), which works on A's vertex
// blocks — a ninth of the index work of a scalar product, and the structure found once per mesh.
#pragma once

#include <petscmat.h>

#include <cstddef>
#include <memory>
#include <vector>

#include "core/petsc_handle.hpp"

namespace snede {

// An interpolation from coarse unknowns to a fine mesh's vertices: vertex v takes from each of
// its coarse node copies c a dim × n_c block (column p of the copy is coarse unknown
// first_column[c] + p).
struct BlockInterpolation {
  int dim = 3;
  std::vector<PetscInt> first_column;  // per copy, and the number of coarse unknowns last
  std::vector<std::size_t> start;      // per fine vertex: its entries (n_points + 1)
  std::vector<PetscInt> copy;          // per entry
  std::vector<double> block;           // per entry: dim × dim, row-major; columns from n_c on are 0
  PetscInt n_copies() const { return static_cast<PetscInt>(first_column.size()) - 1; }
  PetscInt columns(PetscInt c) const { return first_column[c + 1] - first_column[c]; }
};

class CoarseProduct {
 public:
  virtual ~CoarseProduct() = default;
  // Pᵀ A P from A's current values (A keeps the structure it had when the product was made).
  virtual void recompute() = 0;
  virtual Mat matrix() const = 0;
};

// PETSc's MatPtAP with the "rap" algorithm (P transposed once, then R·(A·P)): twice as fast as
// PETSc's default on the grid levels.
std::unique_ptr<CoarseProduct> petsc_galerkin_product(Mat A, Mat P);

// Pᵀ A P for A a SeqBAIJ matrix of block size dim (AssembledTangent's MatrixFormat::baij: a
// block per pair of neighbouring vertices) and P given by `blocks`. `blocks` must outlive the
// product. Throws std::logic_error for any other A.
std::unique_ptr<CoarseProduct> block_galerkin_product(Mat A, const BlockInterpolation& blocks);

}  // namespace snede
