// The first Piola-Kirchhoff view of a material for a D-dimensional element: energy density
// W(F), P(F) and dP(F)[dF]. Materials written in C (hyperelastic, §4.3) go through
// P = F S and dP = dF S + F (∂S/∂C : (dFᵀF + FᵀdF)) (4.4); LinearElastic is written in F.
//
// Plane stress (2D, §6.3.1): the in-plane C₂ = FᵀF is extended to C = diag(C₂, c) with c
// chosen so that S₃₃ = 0 (each material's plane_stress_c33: closed form for St. Venant-
// Kirchhoff and neo-Hookean, a scalar Newton solve for Veronda-Westmann). Because
// ∂W/∂c = S₃₃/2 = 0 there, W₂(C₂) = W(C) has S₂ = the in-plane block of S. Its
// derivative needs dc: differentiating S₃₃ = 0 gives
// dc = −(∂S/∂C : diag(H₂, 0))₃₃ / (∂S/∂C : e₃⊗e₃)₃₃.
//
// F may have more rows than columns (Gradient<T, R, D>): the 3 × 2 F of a membrane
// (fem/membrane_kernel.hpp) enters only through C₂ = FᵀF, P = F S and
// dP = dF S + F dS, the same formulas. LinearElastic is written in a square F only.
#pragma once

#include <concepts>
#include <type_traits>
#include <utility>

#include "fem/batch.hpp"
#include "fem/tensor.hpp"

namespace snede {

template <class M>
concept WrittenInC = requires(const M& m, const Tensor<double, 3>& C) {
  { m.stress(C) };
};

// C₃₃ in plane stress. On a Batch, a material that finds it by iteration (Newton steps that
// branch element by element) is run lane by lane; closed forms run on all lanes at once.
template <class T, class M>
T plane_stress_c33(const M& m, const Tensor<T, 2>& C2) {
  if constexpr (std::is_same_v<T, Batch> && !M::plane_stress_c33_closed_form)
    return Batch::from_lanes([&](int lane) { return m.plane_stress_c33(lane_of(C2, lane)); });
  else
    return m.plane_stress_c33(C2);
}

template <class T, int D, class M, int R>
Tensor<T, 3> right_cauchy_green_3d(const M& m, const Gradient<T, R, D>& F) {
  if constexpr (D == 3) {
    return F.transpose() * F;
  } else {
    Tensor<T, 3> C = Tensor<T, 3>::Zero();
    const Tensor<T, 2> C2 = F.transpose() * F;
    C.template topLeftCorner<2, 2>() = C2;
    C(2, 2) = plane_stress_c33<T>(m, C2);
    return C;
  }
}

template <class T, int D, class M, int R>
T energy_density(const M& m, const Gradient<T, R, D>& F) {
  if constexpr (WrittenInC<M>)
    return m.energy(right_cauchy_green_3d<T, D>(m, F));
  else
    return m.template energy<T, D>(F);
}

template <class T, int D, class M, int R>
Tensor<T, D> second_piola(const M& m, const Gradient<T, R, D>& F) {
  if constexpr (WrittenInC<M>)
    return m.stress(right_cauchy_green_3d<T, D>(m, F)).template topLeftCorner<D, D>();
  else
    return m.template second_piola<T, D>(F);
}

template <class T, int D, class M, int R>
Gradient<T, R, D> first_piola(const M& m, const Gradient<T, R, D>& F) {
  if constexpr (WrittenInC<M>)
    return F * second_piola<T, D>(m, F);
  else
    return m.template first_piola<T, D>(F);
}

// The material's ∂S/∂C at one C as a map of H (its stress_tangent(C)); nothing for a material
// written in F.
template <class T, class M>
struct StressTangentOf {
  struct type {};
};
template <class T, WrittenInC M>
struct StressTangentOf<T, M> {
  using type = decltype(std::declval<const M&>().stress_tangent(std::declval<const Tensor<T, 3>&>()));
};

// dP(F)[dF] as a linear map of dF at one F, with the work that depends on F alone done once
// (C, S, the material's ∂S/∂C at C, plane stress's c₃₃ and its derivative's denominator): an
// element stiffness applies it to D² (or more) directions.
template <class T, int D, class M, int R>
class FirstPiolaTangent {
 public:
  FirstPiolaTangent(const M& m, const Gradient<T, R, D>& F) : m_(m), F_(F) {
    if constexpr (WrittenInC<M>) {
      const Tensor<T, 3> C = right_cauchy_green_3d<T, D>(m, F);
      S_ = m.stress(C).template topLeftCorner<D, D>();
      dS_of_ = m.stress_tangent(C);
      if constexpr (D == 2) {
        Tensor<T, 3> e33 = Tensor<T, 3>::Zero();
        e33(2, 2) = T(1);
        c33_slope_ = dS_of_(e33)(2, 2);
      }
    }
  }
  Gradient<T, R, D> operator()(const Gradient<T, R, D>& dF) const {
    if constexpr (WrittenInC<M>) {
      Tensor<T, 3> H = Tensor<T, 3>::Zero();
      H.template topLeftCorner<D, D>() = dF.transpose() * F_ + F_.transpose() * dF;
      if constexpr (D == 2) H(2, 2) = -dS_of_(H)(2, 2) / c33_slope_;
      const Tensor<T, D> dS = dS_of_(H).template topLeftCorner<D, D>();
      return dF * S_ + F_ * dS;
    } else {
      return m_.template first_piola_derivative<T, D>(F_, dF);
    }
  }

 private:
  const M& m_;
  Gradient<T, R, D> F_;
  Tensor<T, D> S_;
  typename StressTangentOf<T, M>::type dS_of_;
  T c33_slope_{};  // (∂S/∂C : e₃⊗e₃)₃₃ (plane stress)
};

template <class T, int D, class M, int R>
Gradient<T, R, D> first_piola_derivative(const M& m, const Gradient<T, R, D>& F, const Gradient<T, R, D>& dF) {
  return FirstPiolaTangent<T, D, M, R>(m, F)(dF);
}

}  // namespace snede
