// Dynamic relaxation (§2.5, §4.1, §4.4.1) on one tetrahedron with three fixed corners: a
// three-dof mass-spring system whose stiffness (the element matrix) and mass (a quarter of
// the element's) give the static solution and the stability limit 2/√λ_max(M⁻¹K) exactly.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <optional>

#include "core/error.hpp"
#include "solvers/dynamic_relaxation.hpp"

using namespace snede;

namespace {

constexpr double edge = 0.01, density = 1000.0, gravity = -9.81;

struct Spring {
  Mesh mesh{3, {0, 0, 0, edge, 0, 0, 0, edge, 0, 0, 0, edge}, std::vector<std::int64_t>{0, 1, 2, 3}};
  ElasticBody body{mesh, LinearElastic(3e3, 0.3), density, 0.0};
  Model model{body};
  VertexId apex = 3;
  Eigen::Matrix3d stiffness;  // of the apex
  double mass = density * edge * edge * edge / 6 / 4;

  Spring() {
    const std::vector<VertexId> base{0, 1, 2};
    model.fix(base, {});
    model.set_gravity(std::vector<double>{0, 0, gravity});
    const std::vector<VertexId> cell = mesh.cells();
    const int slot = static_cast<int>(std::find(cell.begin(), cell.end(), apex) - cell.begin());
    const std::vector<double> K = body.element_stiffness(mesh.cell_ids()[0], std::vector<double>(12, 0.0));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) stiffness(i, j) = K[(slot * 3 + i) * 12 + slot * 3 + j];
  }
  Eigen::Vector3d apex_displacement() const {
    const PetscScalar* u = nullptr;
    SNEDE_PETSC(VecGetArrayRead(model.displacement(), &u));
    const Eigen::Vector3d a(u[apex * 3], u[apex * 3 + 1], u[apex * 3 + 2]);
    SNEDE_PETSC(VecRestoreArrayRead(model.displacement(), &u));
    return a;
  }
  double stability_limit() const {
    return 2 / std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(stiffness / mass).eigenvalues().maxCoeff());
  }
};

// A damping η, a step (unset: the CFL estimate) and the test's own options prefix.
DynamicRelaxationOptions relaxation(double damping, std::optional<double> dt, const std::string& prefix) {
  DynamicRelaxationOptions options;
  options.damping = damping;
  options.dt = dt;
  options.options_prefix = prefix;
  return options;
}

}  // namespace

TEST(DynamicRelaxation, SettlesInTheStaticSolutionOfTheSpring) {
  Spring spring;
  DynamicRelaxation dynamics(spring.model, relaxation(200.0, std::nullopt, "cpp_spring_"));
  const SolveResult result = dynamics.run(1e-8, 100000);
  ASSERT_TRUE(result.converged) << result.reason;
  EXPECT_EQ(result.reason, "CONVERGED_FNORM_ABS");
  EXPECT_LE(result.residual_norm, result.tolerance);
  const Eigen::Vector3d expected = spring.stiffness.ldlt().solve(Eigen::Vector3d(0, 0, spring.mass * gravity));
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spring.stiffness).eigenvalues().minCoeff();
  EXPECT_LE((spring.apex_displacement() - expected).norm(), result.residual_norm / smallest);
  EXPECT_LT((spring.apex_displacement() - expected).norm(), 1e-6 * expected.norm());
}

TEST(DynamicRelaxation, StabilityLimitIsTwoOverTheHighestFrequency) {
  Spring spring;
  const double limit = spring.stability_limit();
  DynamicRelaxation below(spring.model, relaxation(0.0, 0.99 * limit, "cpp_below_"));
  const SolveResult bounded = below.step(5000);
  EXPECT_TRUE(bounded.converged) << bounded.reason;
  EXPECT_EQ(bounded.reason, "CONVERGED_ITS");
  EXPECT_EQ(bounded.iterations, 5000);
  SNEDE_PETSC(VecZeroEntries(spring.model.displacement()));
  DynamicRelaxation above(spring.model, relaxation(0.0, 1.01 * limit, "cpp_above_"));
  const SolveResult blown = above.step(5000);
  EXPECT_FALSE(blown.converged);
  EXPECT_EQ(blown.reason, "DIVERGED_BLOW_UP");
  EXPECT_LT(blown.iterations, 5000);
}

TEST(DynamicRelaxation, CriticalStepSearchLandsWithinOneReductionOfTheLimit) {
  Spring spring;
  DynamicRelaxation dynamics(spring.model, relaxation(50.0, std::nullopt, "cpp_search_"));
  const double limit = spring.stability_limit();
  for (double start : {0.0, 0.3 * limit, 3.0 * limit}) {  // from the CFL estimate, below and above
    const double found = dynamics.critical_time_step(2e6, start, 0.15, 200);
    EXPECT_GT(found, 0.85 * limit) << "start " << start;
    EXPECT_LE(found, 1.001 * limit) << "start " << start;
  }
  EXPECT_EQ(dynamics.damping(), 50.0);  // restored after the undamped trials
  EXPECT_EQ(dynamics.time_step(), dynamics.cfl_time_step());
  EXPECT_EQ(spring.apex_displacement().norm(), 0.0);
}

TEST(DynamicRelaxation, OptionsPrefixReachesTheTs) {
  SNEDE_PETSC(PetscOptionsSetValue(nullptr, "-cpp_options_ts_max_steps", "4"));
  SNEDE_PETSC(PetscOptionsSetValue(nullptr, "-cpp_options_ts_ss22_damping", "7.5"));
  Spring spring;
  DynamicRelaxation dynamics(spring.model, relaxation(1.0, std::nullopt, "cpp_options_"));
  TSType type = nullptr;
  SNEDE_PETSC(TSGetType(dynamics.ts(), &type));
  EXPECT_STREQ(type, ts_ss22);
  EXPECT_EQ(dynamics.damping(), 7.5);
  EXPECT_EQ(dynamics.step(10).iterations, 4);
  const SolveResult capped = dynamics.run(1e-8, 10);
  EXPECT_FALSE(capped.converged);
  EXPECT_EQ(capped.reason, "DIVERGED_MAX_IT");
  SNEDE_PETSC(PetscOptionsClearValue(nullptr, "-cpp_options_ts_max_steps"));
  SNEDE_PETSC(PetscOptionsClearValue(nullptr, "-cpp_options_ts_ss22_damping"));
}

TEST(DynamicRelaxation, RejectsNegativeDampingAndStep) {
  Spring spring;
  EXPECT_THROW(DynamicRelaxation(spring.model, relaxation(-1.0, std::nullopt, "dynamic_")), std::invalid_argument);
  EXPECT_THROW(DynamicRelaxation(spring.model, relaxation(1.0, -1e-3, "dynamic_")), std::invalid_argument);
  EXPECT_THROW(DynamicRelaxation(spring.model, relaxation(1.0, std::nan(""), "dynamic_")), std::invalid_argument);
  EXPECT_THROW(DynamicRelaxation(spring.model, relaxation(1.0, 0.0, "dynamic_")), std::invalid_argument);
}
