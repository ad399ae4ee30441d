// Per-element kernels for linear simplices (§2.3): with Z = [x₁ − x₀, …, x_D − x₀] (2.32)
// and U the same differences of displacements, F = I + U Z⁻¹ (2.34). Energy is
// |τ| W(F); the internal forces on nodes 1..D are the columns of −|τ| P Z⁻ᵀ (2.38) and
// node 0 gets minus their sum; the tangent action takes dU to |τ| dP[dU Z⁻¹] Z⁻ᵀ (4.4).
// |τ| is the reference volume, or area × thickness in plane stress. The reference data's
// scalar S is double for one element, or Batch for batch_width elements side by side.
#pragma once

#include <type_traits>

#include "fem/constitutive.hpp"
#include "fem/tensor.hpp"

namespace snede {

template <int D, class S = double>
struct ElementReference {
  Tensor<S, D> Z_inv;
  S measure = 0;  // volume (3D) or area × thickness (2D)
};

// ref's Z⁻¹ as a tensor of T: the stored one itself when S is T (no copy), else cast.
template <class T, int D, class S>
decltype(auto) inverse_shape(const ElementReference<D, S>& ref) {
  if constexpr (std::is_same_v<T, S>)
    return (ref.Z_inv);
  else
    return Tensor<T, D>(ref.Z_inv.template cast<T>());
}

template <class T, int D, class S>
Tensor<T, D> deformation_gradient(const ElementReference<D, S>& ref, const Tensor<T, D>& U) {
  return identity<T, D>() + U * ref.Z_inv.template cast<T>();
}

template <class T, int D, class M, class S>
T element_energy(const M& m, const ElementReference<D, S>& ref, const Tensor<T, D>& U) {
  return T(ref.measure) * energy_density<T, D>(m, deformation_gradient<T, D>(ref, U));
}

// Forces on nodes 1..D as columns (node 0: minus the sum of the columns); −∂(energy)/∂u.
template <class T, int D, class M, class S>
Tensor<T, D> element_force_columns(const M& m, const ElementReference<D, S>& ref, const Tensor<T, D>& U) {
  const Tensor<T, D> P = first_piola<T, D>(m, deformation_gradient<T, D>(ref, U));
  return T(-ref.measure) * P * ref.Z_inv.transpose().template cast<T>();
}

// The tangent action on the direction whose gradient is dF (= dU Z⁻¹) through dP_of, the
// FirstPiolaTangent at the element's F (formed once for several directions: an element
// stiffness, whose unit directions have their dF without a product).
template <class T, int D, class Tangent, class S>
Tensor<T, D> tangent_columns_of_gradient(const Tangent& dP_of, const ElementReference<D, S>& ref, const Tensor<T, D>& dF) {
  const Tensor<T, D> dP = dP_of(dF);
  return T(ref.measure) * dP * inverse_shape<T>(ref).transpose();
}

// Tangent action on nodes 1..D as columns (node 0: minus the sum); ∂²(energy)/∂u² · d.
template <class T, int D, class M, class S>
Tensor<T, D> element_tangent_columns(const M& m, const ElementReference<D, S>& ref, const Tensor<T, D>& U,
                                     const Tensor<T, D>& dU) {
  return tangent_columns_of_gradient<T, D>(FirstPiolaTangent<T, D, M, D>(m, deformation_gradient<T, D>(ref, U)), ref,
                                          Tensor<T, D>(dU * inverse_shape<T>(ref)));
}

}  // namespace snede
