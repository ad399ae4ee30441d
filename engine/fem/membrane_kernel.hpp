// Per-element kernels of an elastic membrane: a linear triangle in 3D (the membranes of
// §5.3, skin or intestine) under plane stress (§6.3.1), with the energy-force-tangent chain
// of §2.3 and §4.3 on a 3 × 2 deformation gradient.
//
// Each reference triangle gets an orthonormal tangent frame T = [t₁ t₂] (t₁ along x₁ − x₀,
// t₂ = n × t₁ with n the normal of its oriented corners) and the 2 × 2 shape matrix
// Z = Tᵀ [X₁ − X₀, X₂ − X₀], so the reference edges are T Z. With U the 3 × 2 displacement
// differences, F = T + U Z⁻¹ maps tangent coordinates to deformed positions (3 × 2).
// The hyperelastic energy is |τ| W₂(C₂) with C₂ = FᵀF and W₂ the plane-stress energy of
// constitutive.hpp: it depends on F only through C₂, so a rotation of the deformed
// triangle in 3D (F → QF) changes nothing, and P = F S₂, dP = dF S₂ + F dS₂ are the
// volume formulas on a 3 × 2 F. Working with C₂ rather than a 2 × 2 F̂ (the R of F = QR)
// avoids differentiating a QR decomposition; the two give the same energy (F̂ᵀF̂ = C₂).
//
// LinearElastic stays small-strain: ε = sym(Tᵀ U Z⁻¹), the in-plane part of the surface
// displacement gradient in the reference frame. It has no out-of-plane stiffness at all (a
// normal displacement changes no ε), so a flat linear membrane needs supports that hold
// every vertex out of plane, and cannot carry a transverse load (pre-tension is a
// nonlinear effect: use a hyperelastic material for a membrane loaded across its plane).
//
// Inversion: a triangle in 3D has no inside; a mirror image of it is a rotation of it, so
// "normal flipped relative to the reference" would call a rigid half-turn inverted. The
// only loss of orientation a membrane element can suffer is collapse, zero area:
// det C₂ = |F e₁ × F e₂|² = 0 (the det F̂ ≤ 0 of the volume kernels, F̂ᵀF̂ = C₂), where the
// neo-Hookean and Veronda-Westmann energies go to +∞ as for an inverted volume element.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>

#include "fem/constitutive.hpp"
#include "fem/linear_elastic.hpp"

namespace snede {

// Differences of a nodal field over a triangle in 3D (columns: corners 1, 2 minus corner
// 0), and forces or tangent actions on corners 1, 2 as columns (corner 0: minus their sum).
template <class T>
using MembraneColumns = Gradient<T, 3, 2>;

struct MembraneReference {
  Gradient<double, 3, 2> frame = Gradient<double, 3, 2>::Identity();  // T
  Tensor<double, 2> Z_inv = Tensor<double, 2>::Identity();
  double measure = 0;  // area × thickness
};

// From the reference corners, oriented (the frame's normal is (x₁ − x₀) × (x₂ − x₀)).
// Z is written out from the frame's construction: Z = [[|e₁|, t₁·e₂], [0, 2A/|e₁|]].
inline MembraneReference membrane_reference(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                                            const Eigen::Vector3d& x2, double thickness) {
  const Eigen::Vector3d e1 = x1 - x0, e2 = x2 - x0, normal = e1.cross(e2);
  const double twice_area = normal.norm(), length = e1.norm();
  MembraneReference ref;
  ref.frame.col(0) = e1 / length;
  ref.frame.col(1) = (normal / twice_area).cross(ref.frame.col(0));
  Tensor<double, 2> Z;
  Z << length, ref.frame.col(0).dot(e2), 0.0, twice_area / length;
  ref.Z_inv = Z.inverse();
  ref.measure = 0.5 * twice_area * thickness;
  return ref;
}

template <class T>
MembraneColumns<T> membrane_deformation_gradient(const MembraneReference& ref, const MembraneColumns<T>& U) {
  return ref.frame.template cast<T>() + U * ref.Z_inv.template cast<T>();
}

// Collapsed: the deformed area |F₁ × F₂| (per unit reference area; √det C₂) is round-off,
// at most 64ε·max(1, |F₁||F₂|) — a few ulps of the reference area (F is of size 1 at rest)
// or of its deformed edges' parallelogram, the scale of Mesh's zero-area test
// (mesh/element_quality.hpp). Exactly zero is never seen: F = T + U Z⁻¹ rounds. A non-finite
// state is not "collapsed": the loops report its non-finite result as a domain error, as
// for volumes.
inline bool membrane_collapsed(const MembraneReference& ref, const MembraneColumns<double>& U) {
  const MembraneColumns<double> F = membrane_deformation_gradient<double>(ref, U);
  const double area_squared = F.col(0).cross(F.col(1)).squaredNorm();
  const double scale_squared = std::max(1.0, F.col(0).squaredNorm() * F.col(1).squaredNorm());
  constexpr double tolerance = 64 * std::numeric_limits<double>::epsilon();
  return area_squared <= tolerance * tolerance * scale_squared;
}

// Small-strain gradient in the reference frame, Tᵀ U Z⁻¹ (LinearElastic).
template <class T>
Tensor<T, 2> membrane_in_plane_gradient(const MembraneReference& ref, const MembraneColumns<T>& U) {
  return ref.frame.transpose().template cast<T>() * U * ref.Z_inv.template cast<T>();
}

template <class T, class M>
T membrane_energy(const M& m, const MembraneReference& ref, const MembraneColumns<T>& U) {
  if constexpr (is_linear_elastic<M>)
    return T(ref.measure) * m.template energy_of_gradient<T, 2>(membrane_in_plane_gradient<T>(ref, U));
  else
    return T(ref.measure) * energy_density<T, 2>(m, membrane_deformation_gradient<T>(ref, U));
}

// −∂(energy)/∂u on corners 1, 2.
template <class T, class M>
MembraneColumns<T> membrane_force_columns(const M& m, const MembraneReference& ref, const MembraneColumns<T>& U) {
  const Tensor<T, 2> Z_inv_t = ref.Z_inv.transpose().template cast<T>();
  if constexpr (is_linear_elastic<M>)
    return -ref.frame.template cast<T>() *
           m.template stress_of_gradient<T, 2>(membrane_in_plane_gradient<T>(ref, U), T(ref.measure)) * Z_inv_t;
  else
    return T(-ref.measure) * first_piola<T, 2>(m, membrane_deformation_gradient<T>(ref, U)) * Z_inv_t;
}

// ∂²(energy)/∂u² · d on corners 1, 2; dU the differences of d.
template <class T, class M>
MembraneColumns<T> membrane_tangent_columns(const M& m, const MembraneReference& ref, const MembraneColumns<T>& U,
                                            const MembraneColumns<T>& dU) {
  const Tensor<T, 2> Z_inv = ref.Z_inv.template cast<T>();
  if constexpr (is_linear_elastic<M>) {
    return ref.frame.template cast<T>() *
           m.template stress_of_gradient<T, 2>(membrane_in_plane_gradient<T>(ref, dU), T(ref.measure)) *
           Z_inv.transpose();
  } else {
    const MembraneColumns<T> dF = dU * Z_inv;
    return T(ref.measure) * first_piola_derivative<T, 2>(m, membrane_deformation_gradient<T>(ref, U), dF) *
           Z_inv.transpose();
  }
}

// The in-plane stress in the reference frame T: S₂ (second Piola-Kirchhoff), or σ for
// LinearElastic.
template <class T, class M>
Tensor<T, 2> membrane_stress(const M& m, const MembraneReference& ref, const MembraneColumns<T>& U) {
  if constexpr (is_linear_elastic<M>)
    return m.template stress_of_gradient<T, 2>(membrane_in_plane_gradient<T>(ref, U));
  else
    return second_piola<T, 2>(m, membrane_deformation_gradient<T>(ref, U));
}

}  // namespace snede
