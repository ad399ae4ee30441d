// Compressible neo-Hookean (4.6): W = ½ (μ (ι₁ − 3) − μ ln ι₃ + λ (J − 1)²), J = √ι₃,
// S = μ I + (λ (J − 1) J − μ) C⁻¹,
// ∂S/∂C : H = −(λ (J − 1) J − μ) C⁻¹ H C⁻¹ + λ/2 (2J − 1) J (C⁻¹ : H) C⁻¹.
#pragma once

#include <cmath>

#include "fem/lame.hpp"
#include "fem/tensor.hpp"

namespace snede {

struct NeoHookean {
  Lame lame;
  static constexpr bool plane_stress_c33_closed_form = true;
  static constexpr bool forbids_inversion = true;
  static constexpr const char* name = "NeoHookean";

  NeoHookean(double young, double poisson) : lame(lame_from_young_poisson(young, poisson)) {}

  template <class T>
  T energy(const Tensor<T, 3>& C) const {
    using std::log;
    using std::sqrt;
    const T i3 = C.determinant();
    const T J = sqrt(i3);
    return T(0.5) * (T(lame.mu) * (C.trace() - T(3)) - T(lame.mu) * log(i3) + T(lame.lambda) * (J - T(1)) * (J - T(1)));
  }
  template <class T>
  Tensor<T, 3> stress(const Tensor<T, 3>& C) const {
    using std::sqrt;
    const T J = sqrt(C.determinant());
    return T(lame.mu) * identity<T, 3>() + (T(lame.lambda) * (J - T(1)) * J - T(lame.mu)) * inverse<T, 3>(C);
  }
  // ∂S/∂C : H at one C, with C⁻¹ and the coefficients computed once (an element stiffness
  // applies it to several H).
  template <class T>
  struct StressTangent {
    Tensor<T, 3> C_inv;
    T minus_a, b;  // −(λ (J − 1) J − μ) and λ/2 (2J − 1) J
    Tensor<T, 3> operator()(const Tensor<T, 3>& H) const {
      const Tensor<T, 3> C_inv_H_C_inv = C_inv * H * C_inv;
      return minus_a * C_inv_H_C_inv + b * double_dot<T, 3>(C_inv, H) * C_inv;
    }
  };
  template <class T>
  StressTangent<T> stress_tangent(const Tensor<T, 3>& C) const {
    using std::sqrt;
    const T J = sqrt(C.determinant());
    return {inverse<T, 3>(C), -(T(lame.lambda) * (J - T(1)) * J - T(lame.mu)), T(0.5 * lame.lambda) * (T(2) * J - T(1)) * J};
  }
  // Plane stress: with C = diag(C₂, c), d = det C₂ and s = √c, S₃₃ = 0 reads
  // (μ + λ d) s² − λ √d s − μ = 0, whose positive root is taken (closed form), divided by μ
  // (r = λ/μ): λ² overflows from E = 1e155 Pa and underflows below E = 1e-160 Pa.
  template <class T>
  T plane_stress_c33(const Tensor<T, 2>& C2) const {
    using std::sqrt;
    const T d = C2.determinant();
    const double r = lame.lambda / lame.mu;
    const T a = T(1) + T(r) * d;
    const T root_d = sqrt(d);
    const T s = (T(r) * root_d + sqrt(T(r * r) * d + T(4) * a)) / (T(2) * a);
    return s * s;
  }
};

}  // namespace snede
