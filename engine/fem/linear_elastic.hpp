// Linear geometry and linear material (§3.1, §4.3.2): small strain ε = sym(F − I),
// W = μ ε:ε + λ/2 (tr ε)², stress σ = 2μ ε + λ tr(ε) I used as the first Piola-Kirchhoff
// stress. In plane stress (§6.3.1) σ₃₃ = 0 eliminates ε₃₃ = −λ/(λ+2μ) tr ε, which leaves
// the same formulas in 2D with λ replaced by λ* = 2λμ/(λ + 2μ) (closed form).
#pragma once

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
    const Tensor<T, D> eps = strain<T, D>(F);
    const T trace = eps.trace();
    return T(lame.mu) * double_dot<T, D>(eps, eps) + T(0.5 * effective_lambda<D>()) * trace * trace;
  }
  template <class T, int D>
  Tensor<T, D> first_piola(const Tensor<T, D>& F) const {
    return stress_of<T, D>(strain<T, D>(F));
  }
  template <class T, int D>
  Tensor<T, D> first_piola_derivative(const Tensor<T, D>&, const Tensor<T, D>& dF) const {
    return stress_of<T, D>(T(0.5) * (dF + dF.transpose()));
  }
  // The stress reported per element: σ (the linear theory does not tell S from σ).
  template <class T, int D>
  Tensor<T, D> second_piola(const Tensor<T, D>& F) const {
    return first_piola<T, D>(F);
  }

 private:
  template <class T, int D>
  static Tensor<T, D> strain(const Tensor<T, D>& F) {
    return T(0.5) * (F + F.transpose()) - identity<T, D>();
  }
  template <class T, int D>
  Tensor<T, D> stress_of(const Tensor<T, D>& eps) const {
    return T(2 * lame.mu) * eps + T(effective_lambda<D>()) * eps.trace() * identity<T, D>();
  }
};

}  // namespace snede
