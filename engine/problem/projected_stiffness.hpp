// What the serial and the distributed assembled tangents (tangent_assembly.hpp,
// distributed_assembly.hpp) share: J = P K P + c (I − P) needs each vertex's block of the
// constraints' projection P and of I − P, the constrained directions' stiffness c, the element
// stiffnesses projected on both sides (P_a K_ab P_b), and, for a preconditioner on a membrane,
// an element matrix's positive part.
#pragma once

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include "fem/elastic_body.hpp"
#include "problem/constraints.hpp"

namespace snede {

// A membrane's element tangent is indefinite wherever the sheet is compressed (it has no
// bending stiffness to resist wrinkling), and multigrid built from it made CG's directions
// useless (DIVERGED_LINE_SEARCH at once on a hanging box skin). A preconditioner takes each
// membrane element matrix's positive part instead (its negative eigenvalues raised to a small
// floor: projected Newton, Teran et al. 2005); the operator of every solve stays the exact
// tangent.
class MembranePositivePart {
 public:
  static constexpr int n = 9;  // 3 corners × 3 components
  // Eigenvalues are raised to at least this fraction of the element's largest: a slack element
  // has none across the sheet, and a singular coarse operator made mg fail on a sheet loaded
  // across its plane before it was stretched (studies/benchmarks/membrane_preconditioners.py: with 1e-4
  // it converged at 128 and 512 triangles, with 0 at 512 only). Measured 0, 1e-4, 1e-3, 1e-2,
  // 1e-1: 1e-4 took the fewest iterations on the taut and the sagging sheets and the
  // membrane-cut scene (574 Newton iterations against 615 with 0 and 851 with 1e-3).
  static constexpr double slack_floor = 1e-4;
  std::span<const double> operator()(std::span<const double> K) {
    const Eigen::Map<const Eigen::Matrix<double, n, n, Eigen::RowMajor>> matrix(K.data());
    solver_.compute(matrix);
    const Eigen::Matrix<double, n, 1> positive =
        solver_.eigenvalues().cwiseMax(slack_floor * std::max(solver_.eigenvalues().maxCoeff(), 0.0));
    Eigen::Map<Eigen::Matrix<double, n, n, Eigen::RowMajor>>(part_.data()) =
        solver_.eigenvectors() * positive.asDiagonal() * solver_.eigenvectors().transpose();
    return part_;
  }

 private:
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, n, n>> solver_;
  std::array<double, n * n> part_{};
};

// The stiffness c of the constrained directions (issue 48 item 8): the static problem is
//   F(u) = P ∇Π(u) + c (I − P)(u − ū),   J = P K(u) P + c (I − P),
// with c about a diagonal entry of K, in K's units (N/m), so that the constrained block is of
// the size of the rest whatever the units. With c = 1 (metres in a force residual) the system
// divided by the force scale E·H² had a constrained block 1/(E·h) times its stiffness: from
// E = 1e13 Pa a Chebyshev smoother's eigenvalue estimate (Krylov from a noisy right-hand side,
// Jacobi-scaled: the constrained rows' 1/(c s) dominated it) saw the constrained block alone,
// and 'mg' became indefinite; GAMG's broke down from E = 1e200 (PETSc error 77, "Computed
// maximum singular value as zero").
// c = M ℓ for volume meshes, M = λ + 2μ the material's largest small-strain modulus and
// ℓ = (|Ω| / cells)^(1/3) the mean cell's size (the mean diagonal entry of a P1 stiffness is
// 1.5–4 M ℓ on boxes of 240–6 480 tetrahedra, ν = 0.3–0.49); c = M' t for sheets and
// membranes (plane stress, M' = E/(1 − ν²), t the thickness), whose diagonal entries do not
// depend on the cell size (1.7 M' t on a plane-stress strip). Scale-invariant in the modulus
// and, in 3D, in the length unit (c scales with the lengths as K does). 1 when that is not a
// positive finite number (no cells). Computed once per mesh, never per product.
// volume: |Ω| (the cells' measures summed; read for volume meshes only), cells: their number.
double constraint_stiffness(const Material& material, int cell_dim, double thickness, double volume, double cells);
// |Ω| of a volume mesh: its live cells' volumes summed (0 for a sheet or a membrane).
double volume_of_cells(const Mesh& mesh);

// The blocks of P (dim × dim, row-major) of vertices 0 .. n_points − 1, one after another.
std::vector<double> projection_blocks(const Constraints& constraints, VertexId n_points);

// The (I − P) blocks from the P blocks of projection_blocks.
std::vector<double> complement_blocks(const std::vector<double>& P, int d);

// Calls visit(e, vertices, K_e) for every element of `body` with its stiffness at u projected
// on both sides, P_a K_ab P_b (P: every vertex's block, as projection_blocks gives them), rows
// and columns ordered by the element's oriented vertices, then by component
// (ElasticBody::element_stiffness's order). An element whose vertices are all free (P = I)
// passes its stiffness as it is. Inverted elements of a material that forbids inversion are left
// out, as the shell leaves them out. Given `only` (P1), for those elements alone.
template <class Visit>
void for_each_projected_element_matrix(const ElasticBody& body, std::span<const double> u, std::span<const double> P,
                                       Visit&& visit, const std::vector<ElementId>* only = nullptr) {
  const int d = body.dim();
  std::vector<bool> free(body.mesh().n_points());
  for (std::size_t v = 0; v < free.size(); ++v) {
    free[v] = true;
    for (int i = 0; i < d * d; ++i) free[v] = free[v] && P[v * d * d + i] == (i % (d + 1) == 0 ? 1.0 : 0.0);
  }
  std::vector<double> left, projected;
  auto project = [&](ElementId e, std::span<const VertexId> vertices, std::span<const double> K) {
    if (std::all_of(vertices.begin(), vertices.end(), [&](VertexId v) { return free[v]; })) {
      visit(e, vertices, K);
      return;
    }
    // A P1 element has cell_dim + 1 vertices, a smoothed formulation's patch any number.
    const int corners = static_cast<int>(vertices.size()), n = corners * d;
    left.resize(static_cast<std::size_t>(n) * n);
    projected.resize(static_cast<std::size_t>(n) * n);
    // left = diag(P_a) K, then projected = left diag(P_b): block by block, dim × dim each.
    for (int a = 0; a < corners; ++a)
      for (int col = 0; col < n; ++col)
        for (int i = 0; i < d; ++i) {
          double sum = 0;
          for (int m = 0; m < d; ++m)
            sum += P[(static_cast<std::size_t>(vertices[a]) * d + i) * d + m] * K[static_cast<std::size_t>(a * d + m) * n + col];
          left[static_cast<std::size_t>(a * d + i) * n + col] = sum;
        }
    for (int row = 0; row < n; ++row)
      for (int b = 0; b < corners; ++b)
        for (int j = 0; j < d; ++j) {
          double sum = 0;
          for (int m = 0; m < d; ++m)
            sum += left[static_cast<std::size_t>(row) * n + b * d + m] * P[(static_cast<std::size_t>(vertices[b]) * d + m) * d + j];
          projected[static_cast<std::size_t>(row) * n + b * d + j] = sum;
        }
    visit(e, vertices, std::span<const double>(projected));
  };
  if (only) {
    body.for_each_element_stiffness(u, *only, project);
  } else {
    body.for_each_element_stiffness(u, project);
  }
}

}  // namespace snede
