// Small PETSc conveniences shared by the solvers.
#pragma once

#include <petsctime.h>
#include <petscvec.h>

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace snede {

// ‖v‖₂ over all of v's ranks, scaled by the largest entry as BLAS's dnrm2 is: PETSc's VecNorm
// sums the squares, which underflow below about 1e-154 (the forces on a body with E = 1e-160 Pa)
// and overflow above 1e154, and it caches that wrong norm, which VecCopy and VecScale then carry
// on (a right-hand side of norm 1e-6 looked like 0 to CG). Not cached: PETSc never sees it.
inline double vec_norm(Vec v) {
  const PetscScalar* x = nullptr;
  PetscInt n = 0;
  MPI_Comm comm = MPI_COMM_NULL;
  SNEDE_PETSC(PetscObjectGetComm(reinterpret_cast<PetscObject>(v), &comm));
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  SNEDE_PETSC(VecGetArrayRead(v, &x));
  double largest = 0;
  bool has_nan = false;
  for (PetscInt i = 0; i < n; ++i) {
    has_nan = has_nan || std::isnan(x[i]);
    largest = std::fmax(largest, std::fabs(x[i]));
  }
  double sum = 0;
  MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_DOUBLE, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, &has_nan, 1, MPI_CXX_BOOL, MPI_LOR, comm);
  if (!has_nan && largest > 0 && std::isfinite(largest)) {
    for (PetscInt i = 0; i < n; ++i) sum += (x[i] / largest) * (x[i] / largest);
    MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  }
  SNEDE_PETSC(VecRestoreArrayRead(v, &x));
  if (has_nan) return std::nan("");
  return largest > 0 && std::isfinite(largest) ? largest * std::sqrt(sum) : largest;
}

inline double wall_seconds() {
  PetscLogDouble t = 0;
  SNEDE_PETSC(PetscTime(&t));
  return t;
}

inline double logged_flops() {
  PetscLogDouble flops = 0;
  SNEDE_PETSC(PetscGetFlops(&flops));
  return flops;
}

// Read-only and writable views of a sequential Vec as spans (RAII restore).
class ReadView {
 public:
  explicit ReadView(Vec v) : v_(v) {
    SNEDE_PETSC(VecGetArrayRead(v_, &data_));
    SNEDE_PETSC(VecGetLocalSize(v_, &n_));
  }
  ~ReadView() { VecRestoreArrayRead(v_, &data_); }
  std::span<const double> span() const { return {data_, static_cast<std::size_t>(n_)}; }

 private:
  Vec v_;
  const PetscScalar* data_ = nullptr;
  PetscInt n_ = 0;
};

class WriteView {
 public:
  explicit WriteView(Vec v) : v_(v) {
    SNEDE_PETSC(VecGetArray(v_, &data_));
    SNEDE_PETSC(VecGetLocalSize(v_, &n_));
  }
  ~WriteView() { VecRestoreArray(v_, &data_); }
  std::span<double> span() const { return {data_, static_cast<std::size_t>(n_)}; }

 private:
  Vec v_;
  PetscScalar* data_ = nullptr;
  PetscInt n_ = 0;
};

// A copy of a sequential Vec's values.
inline std::vector<double> vec_values(Vec v) {
  const PetscScalar* data = nullptr;
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  SNEDE_PETSC(VecGetArrayRead(v, &data));
  std::vector<double> values(data, data + n);
  SNEDE_PETSC(VecRestoreArrayRead(v, &data));
  return values;
}

// Sets a sequential Vec's values; throws std::invalid_argument if the sizes differ.
inline void set_vec_values(Vec v, std::span<const double> values) {
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  if (values.size() != static_cast<std::size_t>(n))
    throw std::invalid_argument("expected " + std::to_string(n) + " values (n_points × dim), got " +
                                std::to_string(values.size()));
  PetscScalar* data = nullptr;
  SNEDE_PETSC(VecGetArray(v, &data));
  std::copy(values.begin(), values.end(), data);
  SNEDE_PETSC(VecRestoreArray(v, &data));
}

// Bytes currently allocated through PetscMalloc: tracked only when PETSc runs with
// -malloc_debug (or -malloc_view); 0 otherwise.
inline double petsc_allocated_bytes() {
  PetscLogDouble bytes = 0;
  SNEDE_PETSC(PetscMallocGetCurrentUsage(&bytes));
  return bytes;
}

}  // namespace snede
