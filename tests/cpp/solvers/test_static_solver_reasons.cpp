// What the static solver reports (§ "results, not crashes"): a converged solve says so with
// PETSc's own positive reason; a solve stopped by a too-small iteration limit is not converged
// and reports the KSP's or SNES's reason for it; a state with an inverted element is never
// reported converged, whatever PETSc said.
#include <gtest/gtest.h>

#include <petscksp.h>
#include <petscsnes.h>

#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "solvers/static_solver.hpp"
#include "topology/refinement_checks.hpp"

using namespace snede;

namespace {

// A unit cube of neo-Hookean or linear material hanging from x = 0 under gravity.
struct HangingCube {
  Mesh mesh = snede::testing::kuhn_cube(3);
  ElasticBody body;
  Model model;

  explicit HangingCube(Material material) : body(mesh, material, 1000.0, 0.0), model(body) {
    std::vector<VertexId> fixed;
    for (VertexId v = 0; v < mesh.n_points(); ++v)
      if (mesh.point(v)[0] == 0.0) fixed.push_back(v);
    model.fix(fixed, {});
    model.set_gravity(std::vector<double>{0.0, 0.0, -9.81});
  }
};

StaticOptions options_of(StaticMethod method, int max_iterations, const std::string& prefix) {
  StaticOptions options;
  options.method = method;
  options.max_iterations = max_iterations;
  options.stopping.rtol = 1e-10;
  options.preconditioner = "none";
  options.options_prefix = prefix;
  return options;
}

// A solve of the hanging cube (linear for linear CG, else neo-Hookean) and PETSc's reason for
// how it ended, with its name (the prefix KSP_ or SNES_ dropped).
struct Outcome {
  SolveResult result;
  int petsc_reason = 0;
  std::string petsc_name;
};

Outcome hanging_cube_solve(StaticMethod method, int max_iterations) {
  const bool linear = method == StaticMethod::linear_cg;
  HangingCube cube(linear ? Material(LinearElastic(1e4, 0.3)) : Material(NeoHookean(1e4, 0.3)));
  StaticSolver solver(cube.model, options_of(method, max_iterations, "cpp_reasons_"));
  Outcome outcome{solver.solve()};
  if (linear) {
    KSPConvergedReason reason;
    SNEDE_PETSC(KSPGetConvergedReason(solver.ksp(), &reason));
    outcome.petsc_reason = reason;
    outcome.petsc_name = KSPConvergedReasons[reason];
  } else {
    SNESConvergedReason reason;
    SNEDE_PETSC(SNESGetConvergedReason(solver.snes(), &reason));
    outcome.petsc_reason = reason;
    outcome.petsc_name = SNESConvergedReasons[reason];
  }
  return outcome;
}

}  // namespace

TEST(StaticSolverReasons, ConvergedSolvesReportPetscsPositiveReason) {
  for (StaticMethod method : {StaticMethod::linear_cg, StaticMethod::nonlinear_cg, StaticMethod::newton}) {
    SCOPED_TRACE(static_cast<int>(method));
    const Outcome outcome = hanging_cube_solve(method, 10000);
    EXPECT_TRUE(outcome.result.converged) << summary(outcome.result);
    EXPECT_GT(outcome.petsc_reason, 0);
    EXPECT_EQ(outcome.result.reason, outcome.petsc_name);
    EXPECT_LE(outcome.result.residual_norm, outcome.result.tolerance);
  }
}

TEST(StaticSolverReasons, ATooSmallIterationLimitIsNotConvergedAndSaysWhy) {
  const std::pair<StaticMethod, const char*> cases[] = {{StaticMethod::linear_cg, "DIVERGED_ITS"},
                                                        {StaticMethod::nonlinear_cg, "DIVERGED_MAX_IT"},
                                                        {StaticMethod::newton, "DIVERGED_MAX_IT"}};
  for (const auto& [method, expected] : cases) {
    SCOPED_TRACE(expected);
    const Outcome outcome = hanging_cube_solve(method, 1);
    EXPECT_FALSE(outcome.result.converged) << summary(outcome.result);
    EXPECT_LT(outcome.petsc_reason, 0);
    EXPECT_EQ(outcome.petsc_name, expected);
    EXPECT_EQ(outcome.result.reason, expected);
    EXPECT_GT(outcome.result.residual_norm, outcome.result.tolerance);
  }
}

TEST(StaticSolverReasons, AnInvertedStateIsNeverConverged) {
  // Every vertex prescribed, one pushed through the opposite face of its tetrahedron: nothing
  // is left to solve for (F = 0 once the constraints hold), and the state is inverted.
  Mesh mesh(3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, std::vector<std::int64_t>{0, 1, 2, 3});
  ElasticBody body(mesh, NeoHookean(1e4, 0.3), 1000.0, 0.0);
  Model model(body);
  model.fix(std::vector<VertexId>{0, 1, 2, 3}, std::vector<double>{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -2});
  for (StaticMethod method : {StaticMethod::nonlinear_cg, StaticMethod::newton}) {
    SCOPED_TRACE(static_cast<int>(method));
    StaticSolver solver(model, options_of(method, 100, "cpp_reasons_inverted_"));
    const SolveResult result = solver.solve();
    EXPECT_FALSE(result.converged) << summary(result);
    EXPECT_EQ(result.reason, "DIVERGED_INVERTED_ELEMENTS") << summary(result);
  }
}
