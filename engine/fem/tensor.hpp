// Small fixed-size tensors for the element kernels, templated on the scalar so that the
// same code runs in double and in Counted (flop counting).
#pragma once

#include <Eigen/Dense>

namespace snede {

template <class T, int D>
using Mat = Eigen::Matrix<T, D, D>;

template <class T, int D>
T double_dot(const Mat<T, D>& a, const Mat<T, D>& b) {
  return (a.array() * b.array()).sum();
}

template <class T, int D>
Mat<T, D> identity() {
  return Mat<T, D>::Identity();
}

// Inverse of a symmetric positive definite 3×3 (or 2×2) matrix by cofactors.
template <class T, int D>
Mat<T, D> inverse(const Mat<T, D>& a) {
  return a.inverse();
}

}  // namespace snede
