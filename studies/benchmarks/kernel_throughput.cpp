// Benchmark (not a test): element-loop throughput of ElasticBody per material (§2.3, §4.3),
// and the linear tangent product against an assembled BAIJ(3) product in the same run.
//
//     build/cpp/kernel_throughput [--formulation p1|smoothed] [n ...]
//                                       (default: p1; 26 55, Kuhn boxes of 6n³ tetrahedra)
//
// For each box and material prints million tetrahedra per second (one core, best of several
// calls) for the energy, the internal forces and the tangent action, ns per tetrahedron for
// the tangent action and for the element stiffness matrices of for_each_element_stiffness
// (what an assembled preconditioner's rebuild starts with; the visitor only reads them), then ns per tetrahedron
// for the linear tangent and for MatMult on the BAIJ(3) matrix assembled from the same
// element stiffness matrices. The state is the one studies/benchmarks/fem_throughput.py uses: a
// 0.1 m cube, u = 1e-4·N(0, 1) per component, d = N(0, 1).
#include <petscmat.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "best_seconds.hpp"
#include "core/error.hpp"
#include "core/petsc_handle.hpp"
#include "core/petsc_session.hpp"
#include "fem/elastic_body.hpp"
#include "topology/refinement_checks.hpp"

namespace {

using namespace snede;
using benchmarks::best_seconds;

// The BAIJ(3) matrix Σ_e K_e, preallocated exactly from the vertex graph.
Mat assembled_baij(const ElasticBody& body, std::span<const double> u) {
  const Mesh& mesh = body.mesh();
  const VertexId n_points = mesh.n_points();
  std::vector<std::set<VertexId>> neighbours(n_points);
  const std::vector<VertexId> cells = mesh.cells();
  for (std::size_t c = 0; c < cells.size(); c += 4)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) neighbours[cells[c + i]].insert(cells[c + j]);
  std::vector<PetscInt> blocks_per_row(n_points);
  for (VertexId v = 0; v < n_points; ++v) blocks_per_row[v] = static_cast<PetscInt>(neighbours[v].size());
  Mat K;
  SNEDE_PETSC(MatCreateSeqBAIJ(PETSC_COMM_SELF, 3, 3 * n_points, 3 * n_points, 0, blocks_per_row.data(), &K));
  for (ElementId e : mesh.cell_ids()) {
    const auto v = mesh.connectivity().element(e).simplex.oriented_vertices();
    const std::vector<double> Ke = body.element_stiffness(e, u);
    const PetscInt rows[4] = {v[0], v[1], v[2], v[3]};
    SNEDE_PETSC(MatSetValuesBlocked(K, 4, rows, 4, rows, Ke.data(), ADD_VALUES));
  }
  SNEDE_PETSC(MatAssemblyBegin(K, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(K, MAT_FINAL_ASSEMBLY));
  return K;
}

double baij_product_seconds(const ElasticBody& body, std::span<const double> u, std::span<const double> d,
                            int repeats) {
  PetscHandle<Mat, MatDestroy> K(assembled_baij(body, u));
  PetscHandle<Vec, VecDestroy> x, y;
  SNEDE_PETSC(MatCreateVecs(K, x.out(), y.out()));
  PetscScalar* values = nullptr;
  SNEDE_PETSC(VecGetArray(x, &values));
  std::copy(d.begin(), d.end(), values);
  SNEDE_PETSC(VecRestoreArray(x, &values));
  return best_seconds(repeats, [&] { SNEDE_PETSC(MatMult(K, x, y)); });
}

struct LinearAgainstBaij {
  double n_cells, shell_ns, baij_ns;
};

LinearAgainstBaij run_box(int n, Formulation formulation) {
  Mesh mesh = testing::kuhn_cube(n, 0.1);
  const double n_cells = static_cast<double>(mesh.n_cells());
  std::mt19937 rng(0);
  std::normal_distribution<double> normal;
  std::vector<double> u(3 * static_cast<std::size_t>(mesh.n_points())), d(u.size()), out(u.size());
  for (double& x : u) x = 1e-4 * normal(rng);
  for (double& x : d) x = normal(rng);
  const int repeats = n_cells > 5e5 ? 5 : 10;
  const std::vector<Material> materials = {LinearElastic(3e3, 0.3), StVenantKirchhoff(3e3, 0.3),
                                           NeoHookean(3e3, 0.3), VerondaWestmann(3e3, 0.3, 2.0)};
  double linear_tangent_seconds = 0;
  for (const Material& material : materials) {
    ElasticBody body(mesh, material, 1000.0, 0.0, formulation);
    EvaluationReport report;
    const double t_energy = best_seconds(repeats, [&] { body.energy(u, report); });
    const double t_force = best_seconds(repeats, [&] { body.internal_forces(u, out, report); });
    const double t_tangent = best_seconds(repeats, [&] { body.tangent_apply(u, d, out, report); });
    double diagonal_sum = 0;
    const double t_stiffness = best_seconds(repeats, [&] {
      body.for_each_element_stiffness(u, [&](ElementId, std::span<const VertexId>, std::span<const double> K) {
        diagonal_sum += K[0];
      });
    });
    if (std::holds_alternative<LinearElastic>(material)) linear_tangent_seconds = t_tangent;
    const char* name = std::visit([](const auto& m) { return std::decay_t<decltype(m)>::name; }, material);
    std::printf("| %9.0f | %-17s | %8.1f | %8.1f | %8.1f | %8.1f | %8.1f | %6zu |\n", n_cells, name, n_cells / t_energy * 1e-6,
                n_cells / t_force * 1e-6, n_cells / t_tangent * 1e-6, t_tangent / n_cells * 1e9,
                t_stiffness / n_cells * 1e9, report.inverted.size() + report.domain_errors.size());
    std::fflush(stdout);
  }
  ElasticBody linear(mesh, LinearElastic(3e3, 0.3), 1000.0, 0.0);
  const double t_baij = baij_product_seconds(linear, u, d, repeats);
  return {n_cells, linear_tangent_seconds / n_cells * 1e9, t_baij / n_cells * 1e9};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> divisions;
  Formulation formulation = Formulation::p1;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--formulation" && i + 1 < argc)
      formulation = parse_formulation(argv[++i]);
    else
      divisions.push_back(std::atoi(argv[i]));
  }
  if (divisions.empty()) divisions = {26, 55};
  int petsc_argc = 1;
  snede::PetscSession petsc(&petsc_argc, &argv);
  std::printf("| tetrahedra | material | energy M/s | force M/s | tangent M/s | tangent ns/tet | stiffness ns/tet | flagged |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  std::vector<LinearAgainstBaij> linear;
  for (int n : divisions) linear.push_back(run_box(n, formulation));
  std::printf("\n| tetrahedra | linear tangent ns/tet | BAIJ(3) MatMult ns/tet | tangent / BAIJ |\n|---|---|---|---|\n");
  for (const LinearAgainstBaij& row : linear)
    std::printf("| %9.0f | %8.2f | %8.2f | %5.2f |\n", row.n_cells, row.shell_ns, row.baij_ns, row.shell_ns / row.baij_ns);
  return 0;
}
