// Small PETSc conveniences shared by the solvers.
#pragma once

#include <petsctime.h>
#include <petscvec.h>

#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace snede {

inline double vec_norm(Vec v) {
  PetscReal norm = 0;
  SNEDE_PETSC(VecNorm(v, NORM_2, &norm));
  return norm;
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
