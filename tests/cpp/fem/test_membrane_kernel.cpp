// Membrane kernels (fem/membrane_kernel.hpp) against the 2D plane-stress kernels: a random
// triangle in 3D, rotated into the xy plane, with its displacement rotated likewise, must give
// the same energy, and forces and tangent actions rotated back, for every material.
#include <gtest/gtest.h>

#include <random>

#include "fem/linear_elastic_kernel.hpp"
#include "fem/material.hpp"
#include "fem/membrane_kernel.hpp"

using namespace snede;

namespace {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;

template <class M>
double energy_2d(const M& m, const ElementReference<2>& ref, const Tensor<double, 2>& U) {
  if constexpr (is_linear_elastic<M>) return linear_energy<double, 2>(m, ref, U);
  else return element_energy<double, 2>(m, ref, U);
}

template <class M>
Tensor<double, 2> forces_2d(const M& m, const ElementReference<2>& ref, const Tensor<double, 2>& U) {
  if constexpr (is_linear_elastic<M>) return -linear_stiffness_columns<double, 2>(m, ref, U);
  else return element_force_columns<double, 2>(m, ref, U);
}

template <class M>
Tensor<double, 2> tangent_2d(const M& m, const ElementReference<2>& ref, const Tensor<double, 2>& U,
                             const Tensor<double, 2>& dU) {
  if constexpr (is_linear_elastic<M>) return linear_stiffness_columns<double, 2>(m, ref, dU);
  else return element_tangent_columns<double, 2>(m, ref, U, dU);
}

template <class M>
void expect_membrane_equals_plane_stress(const M& m) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  const double thickness = 0.01;
  for (int trial = 0; trial < 100; ++trial) {
    // a triangle in the xy plane (counter-clockwise), its 2D reference and state
    Eigen::Matrix<double, 2, 3> x;
    x << 0, 1 + 0.3 * unit(rng), 0.3 * unit(rng), 0, 0.3 * unit(rng), 1 + 0.3 * unit(rng);
    Tensor<double, 2> Z;
    Z << x.col(1) - x.col(0), x.col(2) - x.col(0);
    if (Z.determinant() < 0.2) continue;
    const ElementReference<2> ref_2d{Z.inverse(), 0.5 * Z.determinant() * thickness};
    Tensor<double, 2> U, dU;
    U << 0.1 * unit(rng), 0.1 * unit(rng), 0.1 * unit(rng), 0.1 * unit(rng);
    dU << unit(rng), unit(rng), unit(rng), unit(rng);
    // the same triangle and fields rotated into a random plane in 3D
    const Matrix3 Q = Eigen::Quaterniond(Eigen::Vector4d(unit(rng), unit(rng), unit(rng), unit(rng)).normalized()).toRotationMatrix();
    auto in_space = [&](const Tensor<double, 2>& columns) -> MembraneColumns<double> {
      return Q.leftCols<2>() * columns;
    };
    const Vector3 origin(unit(rng), unit(rng), unit(rng));
    auto corner = [&](int j) -> Vector3 { return origin + Q.leftCols<2>() * x.col(j); };
    const MembraneReference ref = membrane_reference(corner(0), corner(1), corner(2), thickness);

    EXPECT_TRUE((ref.frame.transpose() * ref.frame).isIdentity(1e-14));
    EXPECT_TRUE((ref.frame * ref.Z_inv.inverse()).isApprox(in_space(Z), 1e-13));
    // The corners are rounded where they are placed, at |x| ≤ 3.3: each edge (length ≥ 0.5)
    // carries a relative error up to ~4ε·3.3/0.5 ≈ 3e-15, the area twice that; 1e-14 (the
    // portable build was 1.06e-15 off, past the former 1e-15).
    EXPECT_NEAR(ref.measure, ref_2d.measure, 1e-14 * ref_2d.measure);

    const double energy = energy_2d(m, ref_2d, U);
    EXPECT_NEAR(membrane_energy<double>(m, ref, in_space(U)), energy, 1e-12 * std::abs(energy)) << M::name;
    const Tensor<double, 2> forces = forces_2d(m, ref_2d, U);
    EXPECT_TRUE(membrane_force_columns<double>(m, ref, in_space(U)).isApprox(in_space(forces), 1e-12)) << M::name;
    const Tensor<double, 2> action = tangent_2d(m, ref_2d, U, dU);
    EXPECT_TRUE(membrane_tangent_columns<double>(m, ref, in_space(U), in_space(dU)).isApprox(in_space(action), 1e-12))
        << M::name;
    EXPECT_FALSE(membrane_collapsed(ref, in_space(U)));
  }
}

}  // namespace

TEST(MembraneKernel, EqualsPlaneStressInAnyPlane) {
  expect_membrane_equals_plane_stress(LinearElastic(3e3, 0.3));
  expect_membrane_equals_plane_stress(StVenantKirchhoff(3e3, 0.3));
  expect_membrane_equals_plane_stress(NeoHookean(3e3, 0.45));
  expect_membrane_equals_plane_stress(VerondaWestmann(3e3, 0.3, 2.0));
}
