// What the assembled tangent's tests share: their constraints and a comparison of matrices.
#pragma once

#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"
#include "problem/model.hpp"

namespace snede::testing {

// Fixed on x = 0, sliding along y on x = 1.
inline void fix_left_slide_right(Model& model) {
  const Mesh& mesh = model.body().mesh();
  std::vector<VertexId> fixed, sliding;
  for (VertexId v = 0; v < mesh.n_points(); ++v) {
    if (mesh.point(v)[0] == 0) fixed.push_back(v);
    if (mesh.point(v)[0] == 1) sliding.push_back(v);
  }
  model.fix(fixed, {});
  const std::vector<double> along_y{0.0, 1.0, 0.0};
  model.slide(sliding, std::span<const double>(along_y.data(), mesh.dim()));
}

// The largest difference between two matrices' entries over the largest entry of the second.
inline double relative_difference(Mat X, Mat Y) {
  MatHandle x, y;
  SNEDE_PETSC(MatConvert(X, MATSEQDENSE, MAT_INITIAL_MATRIX, x.out()));
  SNEDE_PETSC(MatConvert(Y, MATSEQDENSE, MAT_INITIAL_MATRIX, y.out()));
  PetscInt rows = 0, columns = 0;
  SNEDE_PETSC(MatGetSize(x, &rows, &columns));
  const PetscScalar *a = nullptr, *b = nullptr;
  SNEDE_PETSC(MatDenseGetArrayRead(x, &a));
  SNEDE_PETSC(MatDenseGetArrayRead(y, &b));
  double largest = 0, difference = 0;
  for (PetscInt k = 0; k < rows * columns; ++k) {
    largest = std::max(largest, std::abs(b[k]));
    difference = std::max(difference, std::abs(a[k] - b[k]));
  }
  SNEDE_PETSC(MatDenseRestoreArrayRead(x, &a));
  SNEDE_PETSC(MatDenseRestoreArrayRead(y, &b));
  return difference / largest;
}

}  // namespace snede::testing
