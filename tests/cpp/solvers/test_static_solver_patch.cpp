// The linear patch test (§3.3) for the static solver: an affine displacement A x + b prescribed
// on the boundary of a small box with jittered interior vertices is, in equilibrium, that
// affine field everywhere (constant strain, constant stress: every element's forces cancel at
// the interior vertices), for linear CG on linear elasticity and for Newton on a neo-Hookean
// material. The solve starts from rest, so the interior must move there.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "solvers/static_solver.hpp"
#include "topology/refinement_checks.hpp"

using namespace snede;

namespace {

struct PatchCase {
  const char* name;
  StaticMethod method;
  bool neo_hookean;
};

const double A[3][3] = {{1e-3, 2e-4, -3e-4}, {-5e-4, 7e-4, 1e-4}, {3e-4, -2e-4, -6e-4}};
const double b[3] = {1e-4, -2e-4, 3e-4};

double affine(std::span<const double> x, int i) { return A[i][0] * x[0] + A[i][1] * x[1] + A[i][2] * x[2] + b[i]; }

bool on_boundary(std::span<const double> x) {
  for (double c : x)
    if (c == 0.0 || c == 1.0) return true;
  return false;
}

}  // namespace

class StaticSolverPatchTest : public ::testing::TestWithParam<PatchCase> {};

TEST_P(StaticSolverPatchTest, AnAffineBoundaryDisplacementIsAffineEverywhere) {
  const PatchCase c = GetParam();
  Mesh mesh = snede::testing::shuffled_jittered_cube(3, 0.25, 9);
  ElasticBody body(mesh, c.neo_hookean ? Material(NeoHookean(1e3, 0.3)) : Material(LinearElastic(1e3, 0.3)), 1000.0,
                   0.0);
  Model model(body);
  std::vector<VertexId> boundary;
  std::vector<double> values;
  std::size_t interior = 0;
  for (VertexId v = 0; v < mesh.n_points(); ++v) {
    if (!on_boundary(mesh.point(v))) {
      ++interior;
      continue;
    }
    boundary.push_back(v);
    for (int i = 0; i < 3; ++i) values.push_back(affine(mesh.point(v), i));
  }
  ASSERT_EQ(interior, 8u);
  model.fix(boundary, values);
  StaticOptions options;
  options.method = c.method;
  options.stopping.rtol = 1e-13;
  options.preconditioner = "none";
  options.options_prefix = std::string("cpp_patch_") + c.name + "_";
  StaticSolver solver(model, options);
  const SolveResult result = solver.solve();
  ASSERT_TRUE(result.converged) << summary(result);
  const std::vector<double> u = vec_values(model.displacement());
  double error = 0, largest = 0;
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    for (int i = 0; i < 3; ++i) {
      const double expected = affine(mesh.point(v), i);
      error = std::max(error, std::abs(u[v * 3 + i] - expected));
      largest = std::max(largest, std::abs(expected));
    }
  EXPECT_LT(error, 1e-10 * largest) << summary(result);
}

INSTANTIATE_TEST_SUITE_P(Methods, StaticSolverPatchTest,
                         ::testing::Values(PatchCase{"linear_cg", StaticMethod::linear_cg, false},
                                           PatchCase{"newton", StaticMethod::newton, true}),
                         [](const ::testing::TestParamInfo<PatchCase>& info) { return std::string(info.param.name); });
