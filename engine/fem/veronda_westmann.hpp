// Veronda-Westmann as the thesis makes it compressible and stress-free (§4.3.4):
// W = ½ (2μ/γ (e^{γ(ι₁−3)} − 1) − μ (ι₂ − 3) + λ/2 (ι₃ − 1 − ln ι₃)),
// S = (2μ e^{γ(ι₁−3)} − μ ι₁) I + μ C + λ/2 (ι₃ − 1) C⁻¹                          (4.7)
// ∂S/∂C : H = μ (2γ e^{γ(ι₁−3)} − 1) tr(H) I + μ H
//             + λ/2 (ι₃ (C⁻¹ : H) C⁻¹ − (ι₃ − 1) C⁻¹ H C⁻¹)                       (4.8)
// For small strain (C = I + 2ε) S ≈ 2μ ε + (λ + 2μ(2γ − 1)) tr(ε) I: the linear model with
// λ' = λ + 2μ(2γ − 1), consistent with it only for γ = ½ (§4.3.4 notes the inconsistency;
// its γ → 0 coefficient (μ + λ/2) tr(C − I) should read (λ/2 − μ) tr(C − I)).
#pragma once

#include <cmath>

#include "core/counted.hpp"
#include "fem/lame.hpp"
#include "fem/tensor.hpp"

namespace snede {

struct VerondaWestmann {
  Lame lame;
  double gamma;
  static constexpr bool plane_stress_c33_closed_form = false;
  static constexpr bool forbids_inversion = true;
  static constexpr const char* name = "VerondaWestmann";

  VerondaWestmann(double young, double poisson, double gamma_)
      : lame(lame_from_young_poisson(young, poisson)), gamma(gamma_) {
    require_positive("nonlinearity gamma", gamma);
  }

  template <class T>
  T energy(const Tensor<T, 3>& C) const {
    using std::exp;
    using std::log;
    const T i1 = C.trace();
    const T i2 = T(0.5) * (i1 * i1 - double_dot<T, 3>(C, C));
    const T i3 = C.determinant();
    return T(0.5) * (T(2 * lame.mu / gamma) * (exp(T(gamma) * (i1 - T(3))) - T(1)) - T(lame.mu) * (i2 - T(3)) +
                     T(0.5 * lame.lambda) * (i3 - T(1) - log(i3)));
  }
  template <class T>
  Tensor<T, 3> stress(const Tensor<T, 3>& C) const {
    using std::exp;
    const T i1 = C.trace();
    const T i3 = C.determinant();
    return (T(2 * lame.mu) * exp(T(gamma) * (i1 - T(3))) - T(lame.mu) * i1) * identity<T, 3>() + T(lame.mu) * C +
           T(0.5 * lame.lambda) * (i3 - T(1)) * inverse<T, 3>(C);
  }
  // ∂S/∂C : H at one C, with C⁻¹, ι₃ and the exponential computed once (an element stiffness
  // applies it to several H).
  template <class T>
  struct StressTangent {
    Tensor<T, 3> C_inv;
    T trace_coefficient, i3;  // μ (2γ e^{γ(ι₁−3)} − 1), ι₃
    double mu = 0, half_lambda = 0;
    Tensor<T, 3> operator()(const Tensor<T, 3>& H) const {
      return trace_coefficient * H.trace() * identity<T, 3>() + T(mu) * H +
             T(half_lambda) * (i3 * double_dot<T, 3>(C_inv, H) * C_inv - (i3 - T(1)) * (C_inv * H * C_inv));
    }
  };
  template <class T>
  StressTangent<T> stress_tangent(const Tensor<T, 3>& C) const {
    using std::exp;
    const T e = exp(T(gamma) * (C.trace() - T(3)));
    return {inverse<T, 3>(C), T(lame.mu) * (T(2 * gamma) * e - T(1)), C.determinant(), lame.mu, 0.5 * lame.lambda};
  }
  // Plane stress: with C = diag(C₂, c), t = tr C₂, d = det C₂,
  // S₃₃(c) = 2μ e^{γ(t + c − 3)} − μ t + λ/2 (d − 1/c), strictly increasing in c, from −∞
  // at c → 0 to +∞: one root, found per element by Newton's method safeguarded by
  // bisection (no closed form: the exponential).
  template <class T>
  T plane_stress_c33(const Tensor<T, 2>& C2) const {
    using std::exp;
    const T t = C2.trace(), d = C2.determinant();
    auto residual = [&](T c) { return T(2 * lame.mu) * exp(T(gamma) * (t + c - T(3))) - T(lame.mu) * t + T(0.5 * lame.lambda) * (d - T(1) / c); };
    auto slope = [&](T c) { return T(2 * lame.mu * gamma) * exp(T(gamma) * (t + c - T(3))) + T(0.5 * lame.lambda) / (c * c); };
    T lo(0), hi(1), c(1);
    while (residual(hi) < T(0) && hi < T(1e6)) hi = hi * T(2);
    for (int iteration = 0; iteration < 100; ++iteration) {
      const T r = residual(c);
      if (r > T(0)) hi = c; else lo = c;
      T next = c - r / slope(c);
      if (!(next > lo && next < hi)) next = T(0.5) * (lo + hi);
      const T step = next - c;
      c = next;
      if (std::abs(value_of(step)) <= 1e-15 * value_of(c)) break;
    }
    return c;
  }
};

}  // namespace snede
