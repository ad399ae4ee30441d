// Linear elasticity on linear simplices (§3.1, §4.3.2) without the general F/P/dP path of
// element_kernel.hpp: with the displacement gradient H = U Z⁻¹ (2.34 without the I),
// ε = sym H and σ = λ tr ε I + 2μ ε. The element stiffness applied to displacement
// differences dU gives, on nodes 1..D, the columns |τ| σ(sym(dU Z⁻¹)) Z⁻ᵀ (= Bᵀ D B d_e)
// — the same at every state, so the tangent action reads neither u nor F; the internal
// forces are −K u (the same columns for dU = U, negated) and the energy |τ| W(ε) = ½ u_eᵀ K u_e.
#pragma once

#include "fem/element_kernel.hpp"
#include "fem/linear_elastic.hpp"

namespace snede {

// K_e applied to the direction whose gradient is dH = dU Z⁻¹, on nodes 1..D as columns.
template <class T, int D, class S>
Tensor<T, D> linear_stiffness_columns_of_gradient(const LinearElastic& m, const ElementReference<D, S>& ref,
                                                  const Tensor<T, D>& dH) {
  return m.stress_of_gradient<T, D>(dH, T(ref.measure)) * inverse_shape<T>(ref).transpose();
}

// K_e applied to dU, on nodes 1..D as columns (node 0: minus their sum).
template <class T, int D, class S>
Tensor<T, D> linear_stiffness_columns(const LinearElastic& m, const ElementReference<D, S>& ref,
                                      const Tensor<T, D>& dU) {
  return linear_stiffness_columns_of_gradient<T, D>(m, ref, Tensor<T, D>(dU * inverse_shape<T>(ref)));
}

template <class T, int D, class S>
T linear_energy(const LinearElastic& m, const ElementReference<D, S>& ref, const Tensor<T, D>& U) {
  return T(ref.measure) * m.energy_of_gradient<T, D>(U * ref.Z_inv.template cast<T>());
}

}  // namespace snede
