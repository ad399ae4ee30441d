// Linear geometry and linear material (§3.1, §4.3.2): small strain ε = sym(F − I),
// W = μ ε:ε + λ/2 (tr ε)², stress σ = 2μ ε + λ tr(ε) I used as the first Piola-Kirchhoff
// stress. In plane stress (§6.3.1) σ₃₃ = 0 eliminates ε₃₃ = −λ/(λ+2μ) tr ε, which leaves
// the same formulas in 2D with λ replaced by λ* = 2λμ/(λ + 2μ) (closed form).
#pragma once

#include <type_traits>

#include "fem/lame.hpp"
#include "fem/tensor.hpp"

namespace snede {

struct LinearElastic {
  Lame lame;
  static constexpr bool forbids_inversion = false;
  static constexpr const char* name = "LinearElastic";

  LinearElastic(double young, double poisson) : lame(lame_from_young_poisson(young, poisson)) {}

  template <int D>
  double effective_lambda() const {
    return D == 3 ? lame.lambda : 2 * lame.lambda / (lame.lambda + 2 * lame.mu) * lame.mu;  // no λμ: E up to 1e300
  }
  template <class T, int D>
  T energy(const Tensor<T, D>& F) const {
    return energy_of_strain<T, D>(strain<T, D>(F));
  }
  template <class T, int D>
  Tensor<T, D> first_piola(const Tensor<T, D>& F) const {
    return stress_of<T, D>(strain<T, D>(F));
  }
  template <class T, int D>
  Tensor<T, D> first_piola_derivative(const Tensor<T, D>&, const Tensor<T, D>& dF) const {
    return stress_of_gradient<T, D>(dF);
  }
  // The stress reported per element: σ (the linear theory does not tell S from σ).
  template <class T, int D>
  Tensor<T, D> second_piola(const Tensor<T, D>& F) const {
    return first_piola<T, D>(F);
  }
  // s·σ(sym H) and W(sym H) of a displacement gradient H = F − I given as such: small
  // strains lose no digits to the identity (the specialised kernels,
  // fem/linear_elastic_kernel.hpp). The factor s (an element's measure) scales the two Lamé
  // coefficients rather than the D² entries; σ's symmetry is written out.
  template <class T, int D>
  Tensor<T, D> stress_of_gradient(const Tensor<T, D>& H, const T& s = T(1)) const {
    const T mu = T(lame.mu) * s, lambda_trace = T(effective_lambda<D>()) * s * H.trace();
    Tensor<T, D> sigma;
    for (int i = 0; i < D; ++i) {
      sigma(i, i) = T(2) * mu * H(i, i) + lambda_trace;
      for (int j = i + 1; j < D; ++j) sigma(i, j) = sigma(j, i) = mu * (H(i, j) + H(j, i));
    }
    return sigma;
  }
  template <class T, int D>
  T energy_of_gradient(const Tensor<T, D>& H) const {
    return energy_of_strain<T, D>(symmetric_part<T, D>(H));
  }

 private:
  template <class T, int D>
  static Tensor<T, D> symmetric_part(const Tensor<T, D>& H) {
    return T(0.5) * (H + H.transpose());
  }
  template <class T, int D>
  static Tensor<T, D> strain(const Tensor<T, D>& F) {
    return symmetric_part<T, D>(F) - identity<T, D>();
  }
  template <class T, int D>
  T energy_of_strain(const Tensor<T, D>& eps) const {
    const T trace = eps.trace();
    return T(lame.mu) * double_dot<T, D>(eps, eps) + T(0.5 * effective_lambda<D>()) * trace * trace;
  }
  template <class T, int D>
  Tensor<T, D> stress_of(const Tensor<T, D>& eps) const {
    return T(2 * lame.mu) * eps + T(effective_lambda<D>()) * eps.trace() * identity<T, D>();
  }
};

// The kernels take LinearElastic's own path (no F, a tangent independent of the state).
template <class M>
constexpr bool is_linear_elastic = std::is_same_v<M, LinearElastic>;

}  // namespace snede
