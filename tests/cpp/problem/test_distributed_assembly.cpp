// The assembled MPIAIJ tangent of a distributed static problem (problem/distributed_assembly.*)
// against the matrix-free tangent it stands for: on 1, 2 and 3 ranks (ctest runs these under
// mpirun too), J x from the entries equals the shell's product for random x, at two deformed
// states in turn (the second assembly starts from zero, not from the first's values), with
// fixed vertices and vertices sliding along an oblique line (P's blocks not diagonal), for a
// neo-Hookean cube and a plane-stress square. The tolerance is round-off: both sum the same
// element blocks, in another order.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"
#include "core/petsc_util.hpp"
#include "fem/neo_hookean.hpp"
#include "mesh/distributed_box.hpp"
#include "problem/distributed_static.hpp"

using namespace snede;

namespace {

// Fixed at y = 0; sliding along an oblique line at x = 1 (not at y = 0); by serial ids.
DistributedConditions held_and_sliding(const Mesh& serial) {
  const int d = serial.dim();
  DistributedConditions conditions;
  for (VertexId v = 0; v < serial.n_points(); ++v) {
    const std::span<const double> x = serial.point(v);
    if (x[1] == 0) {
      conditions.fixed.push_back(v);
      conditions.fixed_values.insert(conditions.fixed_values.end(), static_cast<std::size_t>(d), 0.0);
    } else if (x[0] == 1) {
      conditions.sliding.push_back(v);
      for (int k = 0; k < d; ++k) conditions.sliding_directions.push_back(1.0 + k);
      conditions.sliding_anchors.insert(conditions.sliding_anchors.end(), static_cast<std::size_t>(d), 0.0);
    }
  }
  return conditions;
}

// A smooth deformation of the serial vertices, `amount` of the box's size.
std::vector<double> deformation(const Mesh& serial, double amount) {
  const int d = serial.dim();
  std::vector<double> u(static_cast<std::size_t>(serial.n_points()) * d);
  for (VertexId v = 0; v < serial.n_points(); ++v) {
    const std::span<const double> x = serial.point(v);
    for (int k = 0; k < d; ++k) u[static_cast<std::size_t>(v) * d + k] = amount * std::sin(2.0 * x[0] + k) * x[1];
  }
  return u;
}

double norm(Vec x) {
  double value = 0;
  SNEDE_PETSC(VecNorm(x, NORM_2, &value));
  return value;
}

void expect_entries_give_the_shells_product(int dim, int n) {
  const Mesh serial = snede::testing::unit_box(dim, n);
  DistributedMesh part = snede::testing::distributed_box(dim, n);
  DistributedStatic problem(part, NeoHookean(1e4, 0.3), 1000.0, dim == 2 ? 0.01 : 0.0, held_and_sliding(serial));
  std::unique_ptr<AssembledProblemTangent> assembled = problem.make_assembled_tangent(MatrixFormat::aij);
  VecHandle x, from_entries, from_shell;
  SNEDE_PETSC(VecDuplicate(problem.state(), x.out()));
  SNEDE_PETSC(VecDuplicate(problem.state(), from_entries.out()));
  SNEDE_PETSC(VecDuplicate(problem.state(), from_shell.out()));
  std::mt19937 random(7 + snede::testing::world_rank());
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (double amount : {0.05, 0.12}) {
    problem.set_displacement(deformation(serial, amount));
    assembled->assemble(problem.state());
    problem.set_linearization_point(problem.state());
    for (int trial = 0; trial < 3; ++trial) {
      {
        const WriteView values(x);
        for (double& value : values.span()) value = uniform(random);
      }
      SNEDE_PETSC(MatMult(assembled->mat(), x, from_entries));
      SNEDE_PETSC(MatMult(problem.tangent(), x, from_shell));
      const double scale = norm(from_shell);
      SNEDE_PETSC(VecAXPY(from_entries, -1.0, from_shell));
      EXPECT_GT(scale, 0.0);
      EXPECT_LE(norm(from_entries), 1e-12 * scale) << "dim " << dim << ", deformation " << amount;
    }
  }
}

}  // namespace

TEST(DistributedAssembly, EntriesGiveTheShellsProductOfANeoHookeanCube) { expect_entries_give_the_shells_product(3, 5); }

TEST(DistributedAssembly, EntriesGiveTheShellsProductOfAPlaneStressSquare) {
  expect_entries_give_the_shells_product(2, 9);
}
