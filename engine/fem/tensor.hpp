// Small fixed-size tensors for the element kernels, templated on the scalar so that the
// same code runs in double and in Counted (flop counting).
#pragma once

#include <Eigen/Dense>

namespace snede {

template <class T, int D>
using Tensor = Eigen::Matrix<T, D, D>;

// A deformation gradient of a D-dimensional element whose points have R ≥ D coordinates:
// square (R = D) for volume elements, 3 × 2 for a triangle in 3D (a membrane).
template <class T, int R, int D>
using Gradient = Eigen::Matrix<T, R, D>;

template <class T, int D>
T double_dot(const Tensor<T, D>& a, const Tensor<T, D>& b) {
  return (a.array() * b.array()).sum();
}

template <class T, int D>
Tensor<T, D> identity() {
  return Tensor<T, D>::Identity();
}

// Inverse of a symmetric positive definite 3×3 (or 2×2) matrix by cofactors.
template <class T, int D>
Tensor<T, D> inverse(const Tensor<T, D>& a) {
  return a.inverse();
}

}  // namespace snede
