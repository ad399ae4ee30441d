// The tangent shell's diagonal (what PCJACOBI takes, computed without forming J) is J's: entry
// i equals e_iᵀ J e_i from the shell's product with the unit vector e_i, on every row — free,
// fixed and sliding vertices — at a random state and an operator scale other than 1, in 2D and
// 3D, for two materials.
#include <gtest/gtest.h>

#include "problem/test_model_cases.hpp"

using namespace snede;
using namespace snede::testing;

class ModelDiagonal : public ::testing::TestWithParam<ModelCase> {};

TEST_P(ModelDiagonal, IsTheProductWithEachUnitVector) {
  LoadedModel m(GetParam());
  std::mt19937 random(4);
  constrain(m, random_values(m.n_dofs(), 0.01, random), random);
  VecHandle x = m.new_vec(), diagonal = m.new_vec(), unit = m.new_vec(), column = m.new_vec();
  set_vec_values(x, random_values(m.n_dofs(), 0.01, random));
  m.model.set_linearization_point(x);
  m.model.set_operator_scale(0.37);
  SNEDE_PETSC(MatGetDiagonal(m.model.tangent(), diagonal));
  std::vector<double> products(static_cast<std::size_t>(m.n_dofs()));
  for (PetscInt i = 0; i < m.n_dofs(); ++i) {
    SNEDE_PETSC(VecZeroEntries(unit));
    SNEDE_PETSC(VecSetValue(unit, i, 1.0, INSERT_VALUES));
    SNEDE_PETSC(VecAssemblyBegin(unit));
    SNEDE_PETSC(VecAssemblyEnd(unit));
    SNEDE_PETSC(MatMult(m.model.tangent(), unit, column));
    products[i] = vec_values(column)[i];
  }
  EXPECT_LT(relative_difference(vec_values(diagonal), products), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Bodies, ModelDiagonal, ::testing::ValuesIn(model_cases),
                         [](const ::testing::TestParamInfo<ModelCase>& info) { return model_case_name(info.param); });
