// Fixed and sliding vertices as projections (§3.1, §6.6, (6.7)): against a model of the same
// body without constraints (F_free = ∇Π, J_free = K) and the tests' own P and anchors,
//   F(u) = P F_free(u) + c (I − P)(u − anchor),   J v = P K P v + c (I − P) v,
//   reactions = (I − P) ∇Π(u),                   enforce(u) = P u + (I − P) anchor,
// at a random state, in 2D and 3D, for two materials (c: Model::constraint_stiffness).
#include <gtest/gtest.h>

#include "problem/test_model_cases.hpp"

using namespace snede;
using namespace snede::testing;

namespace {

// The constrained model and, on the same mesh, a twin without constraints.
struct ConstrainedAndFree {
  LoadedModel constrained;
  ElasticBody free_body;
  Model free;
  std::mt19937 random{3};
  KnownConstraints known;
  std::vector<double> u;

  explicit ConstrainedAndFree(const ModelCase& c)
      : constrained(c),
        free_body(constrained.mesh, constrained.body.material(), 1000.0, c.dim == 2 ? 0.01 : 0.0),
        free(free_body) {
    const std::vector<double> gravity{0.0, -9.81, 0.0};
    free.set_gravity(std::span<const double>(gravity.data(), c.dim));
    known = constrain(constrained, random_values(constrained.n_dofs(), 0.01, random), random);
    u = random_values(constrained.n_dofs(), 0.01, random);
  }

  std::vector<double> free_residual() {
    VecHandle x = constrained.new_vec(), F = constrained.new_vec();
    set_vec_values(x, u);
    EvaluationReport report;
    free.residual(x, F, report);
    return vec_values(F);
  }
};

// a + b
std::vector<double> sum(std::vector<double> a, const std::vector<double>& b) {
  for (std::size_t k = 0; k < a.size(); ++k) a[k] += b[k];
  return a;
}

// c a
std::vector<double> times(double c, std::vector<double> a) {
  for (double& x : a) x *= c;
  return a;
}

}  // namespace

class ModelConstraints : public ::testing::TestWithParam<ModelCase> {};

TEST_P(ModelConstraints, ResidualRowsAreProjectedAndHoldTheAnchors) {
  ConstrainedAndFree m(GetParam());
  ASSERT_GT(m.known.n_fixed, 0u);
  ASSERT_GT(m.known.n_sliding, 0u);
  std::vector<double> offset = m.u;
  for (std::size_t k = 0; k < offset.size(); ++k) offset[k] -= m.known.anchor[k];
  const double c = m.constrained.model.constraint_stiffness();
  const std::vector<double> expected = sum(m.known.project(m.free_residual()), times(c, m.known.complement(offset)));
  VecHandle x = m.constrained.new_vec(), F = m.constrained.new_vec();
  set_vec_values(x, m.u);
  EvaluationReport report;
  m.constrained.model.residual(x, F, report);
  EXPECT_LT(relative_difference(vec_values(F), expected), 1e-12);
}

TEST_P(ModelConstraints, ReactionsAreTheConstrainedPartOfTheGradient) {
  ConstrainedAndFree m(GetParam());
  const std::vector<double> expected = m.known.complement(m.free_residual());
  VecHandle x = m.constrained.new_vec(), R = m.constrained.new_vec();
  set_vec_values(x, m.u);
  m.constrained.model.reaction_forces(x, R);
  EXPECT_LT(relative_difference(vec_values(R), expected), 1e-12);
}

TEST_P(ModelConstraints, TangentIsTheProjectedStiffnessAndTheConstraintStiffnessOnConstrainedMotions) {
  ConstrainedAndFree m(GetParam());
  VecHandle x = m.constrained.new_vec(), v = m.constrained.new_vec(), Kv = m.constrained.new_vec(),
            Jv = m.constrained.new_vec();
  set_vec_values(x, m.u);
  m.free.set_linearization_point(x);
  m.constrained.model.set_linearization_point(x);
  for (int trial = 0; trial < 3; ++trial) {
    const std::vector<double> d = random_values(m.constrained.n_dofs(), 1.0, m.random);
    set_vec_values(v, m.known.project(d));
    SNEDE_PETSC(MatMult(m.free.tangent(), v, Kv));
    const std::vector<double> expected =
        sum(m.known.project(vec_values(Kv)), times(m.constrained.model.constraint_stiffness(), m.known.complement(d)));
    set_vec_values(v, d);
    SNEDE_PETSC(MatMult(m.constrained.model.tangent(), v, Jv));
    EXPECT_LT(relative_difference(vec_values(Jv), expected), 1e-12) << "trial " << trial;
  }
}

TEST_P(ModelConstraints, EnforcingMovesOnlyTheConstrainedMotionsOntoTheAnchors) {
  ConstrainedAndFree m(GetParam());
  const std::vector<double> expected = sum(m.known.project(m.u), m.known.complement(m.known.anchor));
  VecHandle x = m.constrained.new_vec();
  set_vec_values(x, m.u);
  m.constrained.model.enforce_constraints(x);
  EXPECT_LT(relative_difference(vec_values(x), expected), 1e-14);
}

INSTANTIATE_TEST_SUITE_P(Bodies, ModelConstraints, ::testing::ValuesIn(model_cases),
                         [](const ::testing::TestParamInfo<ModelCase>& info) { return model_case_name(info.param); });
