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
#include "problem/distributed_cases.hpp"
#include "problem/distributed_static.hpp"

using namespace snede;
using snede::testing::deformation;
using snede::testing::held_and_sliding;
using snede::testing::norm;

namespace {

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
