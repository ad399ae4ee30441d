// The assembled tangent (tangent_assembly.hpp) in both formats against the shell it stands for:
// on jittered meshes with fixed and sliding vertices, at a random state and an operator scale
// other than 1, the BAIJ matrix has the AIJ one's entries and both apply the shell's J — in 2D
// and 3D, for every material, under the P1 and the smoothed formulation, and on a membrane (its
// exact tangent; the positive part a preconditioner takes has no shell, so the formats are
// compared there). Also after a second assembly at another state (values are refilled in place).
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "fem/material_fixtures.hpp"
#include "problem/tangent_checks.hpp"
#include "problem/tangent_assembly.hpp"
#include "topology/edit_checks.hpp"
#include "topology/refinement_checks.hpp"

using namespace snede;
using snede::testing::relative_difference;

namespace {

enum class Body { square, cube, membrane };

struct Case {
  Body body;
  Formulation formulation;
};

std::string case_name(const Case& c) {
  const char* bodies[] = {"square", "cube", "membrane"};
  return std::string(bodies[static_cast<int>(c.body)]) + "_" + std::string(name_of(c.formulation));
}

Mesh mesh_of(Body body) {
  switch (body) {
    case Body::square: return snede::testing::jittered_square(4, 0.2, 3);
    case Body::cube: return snede::testing::shuffled_jittered_cube(3, 0.2, 5);
    case Body::membrane: return snede::testing::bumpy_surface(4, 0.1, 0.2, 7);
  }
  throw std::logic_error("unknown body");
}

// The largest relative difference between A x and the shell's J x over a few random x.
double product_difference(Model& model, Mat A, std::mt19937& random) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  VecHandle x, ours, shells;
  SNEDE_PETSC(VecDuplicate(model.displacement(), x.out()));
  SNEDE_PETSC(VecDuplicate(x, ours.out()));
  SNEDE_PETSC(VecDuplicate(x, shells.out()));
  double worst = 0;
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<double> entries(static_cast<std::size_t>(model.n_dofs()));
    for (double& e : entries) e = value(random);
    set_vec_values(x, entries);
    SNEDE_PETSC(MatMult(A, x, ours));
    SNEDE_PETSC(MatMult(model.tangent(), x, shells));
    PetscReal reference = 0, difference = 0;
    SNEDE_PETSC(VecNorm(shells, NORM_INFINITY, &reference));
    SNEDE_PETSC(VecAXPY(ours, -1.0, shells));
    SNEDE_PETSC(VecNorm(ours, NORM_INFINITY, &difference));
    worst = std::max(worst, difference / reference);
  }
  return worst;
}

}  // namespace

class AssembledTangentFormats : public ::testing::TestWithParam<Case> {};

TEST_P(AssembledTangentFormats, BlockAndScalarMatricesEqualTheShell) {
  const Case c = GetParam();
  for (const Material& material : snede::testing::all_materials()) {
    SCOPED_TRACE(snede::testing::name_of(material));
    Mesh mesh = mesh_of(c.body);
    const int d = mesh.dim();
    ElasticBody body(mesh, material, 1000.0, mesh.is_surface() || d == 2 ? 0.01 : 0.0, c.formulation);
    Model model(body);
    snede::testing::fix_left_slide_right(model);
    model.set_operator_scale(0.37);
    std::mt19937 random(11);
    std::uniform_real_distribution<double> offset(-0.02, 0.02);
    AssembledTangent aij(model, MatrixFormat::aij), baij(model, MatrixFormat::baij);
    AssembledTangent aij_positive(model, MatrixFormat::aij, MembraneTangent::positive_part);
    AssembledTangent baij_positive(model, MatrixFormat::baij, MembraneTangent::positive_part);
    PetscBool is_baij = PETSC_FALSE;
    SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(baij.mat()), MATSEQBAIJ, &is_baij));
    EXPECT_TRUE(is_baij);
    for (int state = 0; state < 2; ++state) {
      std::vector<double> u(static_cast<std::size_t>(model.n_dofs()));
      for (double& value : u) value = offset(random);
      VecHandle x;
      SNEDE_PETSC(VecDuplicate(model.displacement(), x.out()));
      set_vec_values(x, u);
      model.enforce_constraints(x);
      model.set_linearization_point(x);
      for (AssembledTangent* tangent : {&aij, &baij, &aij_positive, &baij_positive}) tangent->assemble(model, x);
      EXPECT_LT(relative_difference(baij.mat(), aij.mat()), 1e-12);
      EXPECT_LT(product_difference(model, aij.mat(), random), 1e-12);
      EXPECT_LT(product_difference(model, baij.mat(), random), 1e-12);
      EXPECT_LT(relative_difference(baij_positive.mat(), aij_positive.mat()), 1e-12);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Bodies, AssembledTangentFormats,
                         ::testing::Values(Case{Body::square, Formulation::p1}, Case{Body::square, Formulation::smoothed},
                                           Case{Body::cube, Formulation::p1}, Case{Body::cube, Formulation::smoothed},
                                           Case{Body::membrane, Formulation::p1}),
                         [](const ::testing::TestParamInfo<Case>& info) { return case_name(info.param); });
