// St. Venant-Kirchhoff (4.5): W = μ/4 |C − I|² + λ/8 (tr C − 3)²,
// S = μ (C − I) + λ/2 (tr C − 3) I, ∂S/∂C : H = μ H + λ/2 tr(H) I.
#pragma once

#include "fem/lame.hpp"
#include "fem/tensor.hpp"

namespace snede {

struct StVenantKirchhoff {
  Lame lame;
  static constexpr bool plane_stress_c33_closed_form = true;
  static constexpr bool forbids_inversion = false;
  static constexpr const char* name = "StVenantKirchhoff";

  StVenantKirchhoff(double young, double poisson) : lame(lame_from_young_poisson(young, poisson)) {}

  template <class T>
  T energy(const Tensor<T, 3>& C) const {
    const Tensor<T, 3> C_minus_I = C - identity<T, 3>();
    const T t = C.trace() - T(3);
    return T(0.25 * lame.mu) * double_dot<T, 3>(C_minus_I, C_minus_I) + T(0.125 * lame.lambda) * t * t;
  }
  template <class T>
  Tensor<T, 3> stress(const Tensor<T, 3>& C) const {
    return T(lame.mu) * (C - identity<T, 3>()) + T(0.5 * lame.lambda) * (C.trace() - T(3)) * identity<T, 3>();
  }
  // ∂S/∂C : H, the same at every C.
  template <class T>
  struct StressTangent {
    double mu = 0, half_lambda = 0;
    Tensor<T, 3> operator()(const Tensor<T, 3>& H) const {
      return T(mu) * H + T(half_lambda) * H.trace() * identity<T, 3>();
    }
  };
  template <class T>
  StressTangent<T> stress_tangent(const Tensor<T, 3>&) const {
    return {lame.mu, 0.5 * lame.lambda};
  }
  // Plane stress: S₃₃ = μ (c − 1) + λ/2 (tr C₂ + c − 3) = 0 is linear in c = C₃₃, so
  // c = 1 − λ/2 (tr C₂ − 2) / (μ + λ/2) (closed form).
  template <class T>
  T plane_stress_c33(const Tensor<T, 2>& C2) const {
    return T(1) - T(0.5 * lame.lambda / (lame.mu + 0.5 * lame.lambda)) * (C2.trace() - T(2));
  }
};

}  // namespace snede
