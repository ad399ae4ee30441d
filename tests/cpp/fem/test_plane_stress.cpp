// Plane stress (§6.3.1): each material's C₃₃ makes S₃₃ vanish, and the reduction is the
// identity on a state that is already plane.
#include <gtest/gtest.h>

#include <random>

#include "fem/material.hpp"

using namespace snede;

namespace {

template <class M>
void expect_plane_stress(const M& m) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int trial = 0; trial < 200; ++trial) {
    Tensor<double, 2> F;
    F << 1 + jitter(rng), jitter(rng), jitter(rng), 1 + jitter(rng);
    if (F.determinant() <= 0.1) continue;
    const Tensor<double, 2> C2 = F.transpose() * F;
    const double c33 = m.plane_stress_c33(C2);
    ASSERT_GT(c33, 0) << M::name;
    Tensor<double, 3> C = Tensor<double, 3>::Zero();
    C.topLeftCorner<2, 2>() = C2;
    C(2, 2) = c33;
    const Tensor<double, 3> S = m.stress(C);
    EXPECT_NEAR(S(2, 2), 0.0, 1e-12 * S.norm() + 1e-12 * m.lame.mu) << M::name << " trial " << trial;
  }
  // the reference state is plane and stress free: C₃₃ = 1
  EXPECT_NEAR(m.plane_stress_c33(Tensor<double, 2>(Tensor<double, 2>::Identity())), 1.0, 1e-14) << M::name;
}

}  // namespace

TEST(PlaneStress, ThicknessStretchMakesS33Vanish) {
  expect_plane_stress(StVenantKirchhoff(3e3, 0.3));
  expect_plane_stress(NeoHookean(3e3, 0.45));
  expect_plane_stress(VerondaWestmann(3e3, 0.3, 2.0));
  expect_plane_stress(VerondaWestmann(3e3, 0.49, 20.0));
}

TEST(PlaneStress, LinearModelUsesTheReducedLame) {
  const LinearElastic m(3e3, 0.3);
  const double lambda_star = 2 * m.lame.lambda * m.lame.mu / (m.lame.lambda + 2 * m.lame.mu);
  EXPECT_DOUBLE_EQ(m.effective_lambda<2>(), lambda_star);
  EXPECT_DOUBLE_EQ(m.effective_lambda<3>(), m.lame.lambda);
}
