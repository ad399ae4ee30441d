// The model's residual is the gradient of its potential energy and its tangent the derivative
// of the residual (§3.1, §6.6): along a random direction v the Taylor remainders
//   |Π(u + h v) − Π(u) − h F(u)·v|   and   ‖F(u + h v) − F(u) − h J(u) v‖
// fall like h² over h = 2⁻⁵ … 2⁻¹⁰ (like h where F or J is wrong: small enough steps that an
// error of 10⁻⁴ in F·v or J v dominates the remainder). Without constraints F = ∇Π;
// with fixed and sliding vertices F = P∇Π + (I − P)(u − anchor), whose derivative along an
// allowed motion (P v = v) is J v = P K P v. In 2D and 3D, for two materials.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "problem/test_model_cases.hpp"

using namespace snede;
using namespace snede::testing;

namespace {

// log2 of the ratios of successive remainders at h = 2⁻⁵, …, 2⁻¹⁰: 2 for a second-order
// remainder.
std::vector<double> remainder_orders(const std::function<double(double)>& remainder) {
  std::vector<double> orders;
  double previous = remainder(std::ldexp(1.0, -5));
  for (double h = std::ldexp(1.0, -6); h >= std::ldexp(1.0, -10); h /= 2) {
    const double next = remainder(h);
    orders.push_back(std::log2(previous / next));
    previous = next;
  }
  return orders;
}

void expect_second_order(const std::vector<double>& orders) {
  for (double order : orders) EXPECT_NEAR(order, 2.0, 0.02);
}

// A state u and a direction v (allowed motions only when constrained), each random.
struct Probe {
  VecHandle u, v;
};

Probe probe(LoadedModel& m, bool constrained, std::mt19937& random) {
  const std::vector<double> state = random_values(m.n_dofs(), 0.01, random);
  std::vector<double> direction = random_values(m.n_dofs(), 0.01, random);
  if (constrained) direction = constrain(m, state, random).project(direction);
  Probe p{m.new_vec(), m.new_vec()};
  set_vec_values(p.u, state);
  set_vec_values(p.v, direction);
  return p;
}

// u + h v
VecHandle moved(const LoadedModel& m, Vec u, Vec v, double h) {
  VecHandle w = m.new_vec();
  SNEDE_PETSC(VecWAXPY(w, h, v, u));
  return w;
}

}  // namespace

class ModelDerivatives : public ::testing::TestWithParam<ModelCase> {};

TEST_P(ModelDerivatives, ResidualIsTheEnergyGradient) {
  for (bool constrained : {false, true}) {
    SCOPED_TRACE(constrained ? "fixed and sliding vertices" : "no constraints");
    LoadedModel m(GetParam());
    std::mt19937 random(1);
    const Probe p = probe(m, constrained, random);
    EvaluationReport report;
    const double energy = m.model.potential_energy(p.u, report);
    VecHandle F = m.new_vec();
    m.model.residual(p.u, F, report);
    PetscScalar slope = 0;
    SNEDE_PETSC(VecDot(F, p.v, &slope));
    ASSERT_NE(slope, 0.0);
    expect_second_order(remainder_orders([&](double h) {
      EvaluationReport moved_report;
      return std::abs(m.model.potential_energy(moved(m, p.u, p.v, h), moved_report) - energy - h * slope);
    }));
  }
}

TEST_P(ModelDerivatives, TangentIsTheResidualDerivative) {
  for (bool constrained : {false, true}) {
    SCOPED_TRACE(constrained ? "fixed and sliding vertices" : "no constraints");
    LoadedModel m(GetParam());
    std::mt19937 random(2);
    const Probe p = probe(m, constrained, random);
    EvaluationReport report;
    VecHandle F = m.new_vec(), Jv = m.new_vec(), difference = m.new_vec();
    m.model.residual(p.u, F, report);
    m.model.set_linearization_point(p.u);
    SNEDE_PETSC(MatMult(m.model.tangent(), p.v, Jv));
    expect_second_order(remainder_orders([&](double h) {
      m.model.residual(moved(m, p.u, p.v, h), difference, report);
      SNEDE_PETSC(VecAXPY(difference, -1.0, F));
      SNEDE_PETSC(VecAXPY(difference, -h, Jv));
      return vec_norm(difference);
    }));
  }
}

INSTANTIATE_TEST_SUITE_P(Bodies, ModelDerivatives, ::testing::ValuesIn(model_cases),
                         [](const ::testing::TestParamInfo<ModelCase>& info) { return model_case_name(info.param); });
