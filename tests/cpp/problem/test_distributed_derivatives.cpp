// Taylor tests of a distributed static problem (problem/distributed_static.*) on 1, 2 and 3
// ranks (ctest runs them under mpirun too): a neo-Hookean cube and plane-stress square, fixed,
// sliding along an oblique line, under gravity and a nodal force, at a deformed state. Along the
// motions the constraints allow, the residual is the energy's gradient and the shell's tangent
// the residual's derivative: each remainder falls by 4 when the step
// halves (second order; 3.5–4.5 leaves room for the third-order term and round-off, which stays
// below 10⁻⁶ of the smallest remainder here). The energy and the residual's norm are those of
// the same body on one rank (MPI_COMM_SELF) to round-off.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"
#include "core/petsc_util.hpp"
#include "fem/neo_hookean.hpp"
#include "mesh/distributed_box.hpp"
#include "problem/distributed_cases.hpp"
#include "problem/distributed_static.hpp"

using namespace snede;
using snede::testing::deformation;
using snede::testing::held_and_sliding;
using snede::testing::norm;

namespace {

constexpr std::array<double, 3> steps{1e-3, 5e-4, 2.5e-4};

struct Case {
  int dim, n;
  const Mesh serial;
  DistributedMesh part, alone;  // over the world, and the whole box on this rank alone
  DistributedConditions conditions;

  Case(int dim_, int n_)
      : dim(dim_), n(n_), serial(snede::testing::unit_box(dim_, n_)), part(snede::testing::distributed_box(dim_, n_)),
        alone(distribute_mesh(MPI_COMM_SELF, &serial)), conditions(held_and_sliding(serial)) {
    conditions.gravity.assign(static_cast<std::size_t>(dim), 0.0);
    conditions.gravity[1] = -9.81;
    conditions.loaded = {serial.n_points() - 1};
    conditions.forces.assign(static_cast<std::size_t>(dim), 0.5);
  }
  std::unique_ptr<DistributedStatic> problem(DistributedMesh& mesh) const {
    auto made = std::make_unique<DistributedStatic>(mesh, NeoHookean(1e4, 0.3), 1000.0, dim == 2 ? 0.01 : 0.0, conditions);
    made->set_displacement(deformation(serial, 0.05));
    return made;
  }
};

VecHandle copy_of(Vec x) {
  VecHandle copy;
  SNEDE_PETSC(VecDuplicate(x, copy.out()));
  SNEDE_PETSC(VecCopy(x, copy));
  return copy;
}

VecHandle random_like(Vec x, unsigned seed) {
  VecHandle random;
  SNEDE_PETSC(VecDuplicate(x, random.out()));
  std::mt19937 generator(seed + static_cast<unsigned>(snede::testing::world_rank()));
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const WriteView values(random);
  for (double& value : values.span()) value = uniform(generator);
  return random;
}

// Each remainder over the next one (the step halved).
std::vector<double> ratios(const std::array<double, steps.size()>& remainders) {
  std::vector<double> out;
  for (std::size_t k = 0; k + 1 < remainders.size(); ++k) out.push_back(remainders[k] / remainders[k + 1]);
  return out;
}

void expect_second_order(const std::array<double, steps.size()>& remainders, const char* what, int dim) {
  for (double ratio : ratios(remainders)) {
    EXPECT_GT(ratio, 3.5) << what << " in " << dim << "D";
    EXPECT_LT(ratio, 4.5) << what << " in " << dim << "D";
  }
}

void expect_taylor(int dim, int n) {
  Case c(dim, n);
  std::unique_ptr<DistributedStatic> problem = c.problem(c.part);
  const VecHandle u = copy_of(problem->state());
  VecHandle F, shifted, F_shifted, Jd;
  for (VecHandle* v : {&F, &shifted, &F_shifted, &Jd}) SNEDE_PETSC(VecDuplicate(u, v->out()));
  ASSERT_TRUE(problem->residual(u, F).admissible());
  const double energy = problem->energy(u);

  // Energy along an allowed motion: Π(u + h d) − Π(u) − h F·d = O(h²).
  VecHandle allowed = random_like(u, 11);
  problem->project_onto_allowed_motions(allowed);
  double slope = 0;
  SNEDE_PETSC(VecDot(F, allowed, &slope));
  std::array<double, steps.size()> energy_remainders{};
  for (std::size_t k = 0; k < steps.size(); ++k) {
    SNEDE_PETSC(VecWAXPY(shifted, steps[k], allowed, u));
    energy_remainders[k] = std::abs(problem->energy(shifted) - energy - steps[k] * slope);
  }
  expect_second_order(energy_remainders, "energy", dim);

  // Residual along an allowed motion: F(u + h d) − F(u) − h J d = O(h²). (Across the constraints
  // the residual's derivative is P K + c (I − P), the tangent the symmetric P K P + c (I − P).)
  const VecHandle d = random_like(u, 23);
  problem->project_onto_allowed_motions(d);
  problem->set_linearization_point(u);
  SNEDE_PETSC(MatMult(problem->tangent(), d, Jd));
  std::array<double, steps.size()> residual_remainders{};
  for (std::size_t k = 0; k < steps.size(); ++k) {
    SNEDE_PETSC(VecWAXPY(shifted, steps[k], d, u));
    ASSERT_TRUE(problem->residual(shifted, F_shifted).admissible());
    SNEDE_PETSC(VecAXPY(F_shifted, -1.0, F));
    SNEDE_PETSC(VecAXPY(F_shifted, -steps[k], Jd));
    residual_remainders[k] = norm(F_shifted);
  }
  expect_second_order(residual_remainders, "residual", dim);

  // The same body on this rank alone.
  std::unique_ptr<DistributedStatic> alone = c.problem(c.alone);
  VecHandle F_alone;
  SNEDE_PETSC(VecDuplicate(alone->state(), F_alone.out()));
  ASSERT_TRUE(alone->residual(alone->state(), F_alone).admissible());
  EXPECT_NEAR(alone->energy(alone->state()), energy, 1e-12 * std::abs(energy));
  EXPECT_NEAR(norm(F_alone), norm(F), 1e-12 * norm(F));
}

}  // namespace

TEST(DistributedDerivatives, TaylorOfANeoHookeanCube) { expect_taylor(3, 5); }

TEST(DistributedDerivatives, TaylorOfAPlaneStressSquare) { expect_taylor(2, 9); }
