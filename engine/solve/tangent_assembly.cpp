#include "solve/tangent_assembly.hpp"

#include <algorithm>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_util.hpp"

namespace snede {
namespace {

// Every vertex's block of P (dim × dim, row-major), one after another.
std::vector<double> projection_blocks(const Model& model) {
  const int d = model.dim();
  const VertexId n = model.body().mesh().n_points();
  std::vector<double> blocks(static_cast<std::size_t>(n) * d * d);
  for (VertexId v = 0; v < n; ++v)
    model.constraints().projection_block(v, std::span<double>(blocks).subspan(static_cast<std::size_t>(v) * d * d, d * d));
  return blocks;
}

// Calls visit(vertices, K_e) for every element with its stiffness at u projected on both
// sides, P_a K_ab P_b, rows and columns ordered by the element's oriented vertices, then
// by component (ElasticBody::element_stiffness's order). Inverted elements of a material
// that forbids inversion are left out, as the shell leaves them out.
template <class Visit>
void for_each_projected_element_matrix(const Model& model, std::span<const double> u, Visit&& visit) {
  const ElasticBody& body = model.body();
  const Connectivity& c = body.mesh().connectivity();
  const int d = model.dim(), n = (d + 1) * d;
  const std::vector<double> P = projection_blocks(model);
  std::vector<double> left(static_cast<std::size_t>(n) * n);
  std::vector<bool> skipped(c.element_capacity(), false);
  if (forbids_inversion(body.material()))
    for (ElementId e : body.inverted_elements(u)) skipped[e] = true;
  for (ElementId e : body.mesh().cell_ids()) {
    if (skipped[e]) continue;
    const auto vertices = c.element(e).simplex.oriented_vertices();
    std::vector<double> K = body.element_stiffness(e, u);
    // left = diag(P_a) K, then K = left diag(P_b): block by block, dim × dim each.
    for (int a = 0; a <= d; ++a)
      for (int col = 0; col < n; ++col)
        for (int i = 0; i < d; ++i) {
          double sum = 0;
          for (int k = 0; k < d; ++k)
            sum += P[(static_cast<std::size_t>(vertices[a]) * d + i) * d + k] * K[static_cast<std::size_t>(a * d + k) * n + col];
          left[static_cast<std::size_t>(a * d + i) * n + col] = sum;
        }
    for (int row = 0; row < n; ++row)
      for (int b = 0; b <= d; ++b)
        for (int j = 0; j < d; ++j) {
          double sum = 0;
          for (int k = 0; k < d; ++k)
            sum += left[static_cast<std::size_t>(row) * n + b * d + k] * P[(static_cast<std::size_t>(vertices[b]) * d + k) * d + j];
          K[static_cast<std::size_t>(row) * n + b * d + j] = sum;
        }
    visit(std::span<const VertexId>(vertices.data(), d + 1), std::span<const double>(K));
  }
}

}  // namespace

MatHandle create_tangent_matrix(const Model& model, MatrixFormat format) {
  const Mesh& mesh = model.body().mesh();
  const Connectivity& c = mesh.connectivity();
  const int d = model.dim();
  const VertexId n = mesh.n_points();
  std::vector<std::vector<VertexId>> neighbours(n);
  for (VertexId v = 0; v < n; ++v) neighbours[v].push_back(v);
  for (ElementId e : mesh.cell_ids()) {
    const auto vertices = c.element(e).simplex.oriented_vertices();
    for (int a = 0; a <= d; ++a)
      for (int b = 0; b <= d; ++b)
        if (a != b) neighbours[vertices[a]].push_back(vertices[b]);
  }
  std::vector<PetscInt> blocks_per_row(n);
  for (VertexId v = 0; v < n; ++v) {
    auto& list = neighbours[v];
    std::sort(list.begin(), list.end());
    blocks_per_row[v] = static_cast<PetscInt>(std::unique(list.begin(), list.end()) - list.begin());
  }
  MatHandle A;
  const PetscInt rows = static_cast<PetscInt>(n) * d;
  SNEDE_PETSC(MatCreate(PETSC_COMM_SELF, A.out()));
  SNEDE_PETSC(MatSetSizes(A, rows, rows, rows, rows));
  SNEDE_PETSC(MatSetType(A, format == MatrixFormat::baij ? MATSEQBAIJ : MATSEQAIJ));
  SNEDE_PETSC(MatSetBlockSize(A, d));
  SNEDE_PETSC(MatXAIJSetPreallocation(A, d, blocks_per_row.data(), nullptr, nullptr, nullptr));
  SNEDE_PETSC(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE));
  return A;
}

void assemble_tangent(const Model& model, Vec u, Mat A) {
  const int d = model.dim();
  const VertexId n = model.body().mesh().n_points();
  PetscInt rows = 0;
  SNEDE_PETSC(MatGetSize(A, &rows, nullptr));
  if (rows != static_cast<PetscInt>(n) * d)
    throw std::invalid_argument("the tangent matrix has " + std::to_string(rows) + " rows, the body " +
                                std::to_string(static_cast<PetscInt>(n) * d) + " dofs: make it for the current mesh");
  SNEDE_PETSC(MatZeroEntries(A));
  ReadView x(u);
  std::vector<PetscInt> block_rows;
  for_each_projected_element_matrix(model, x.span(), [&](std::span<const VertexId> vertices, std::span<const double> K) {
    block_rows.assign(vertices.begin(), vertices.end());
    const auto count = static_cast<PetscInt>(block_rows.size());
    SNEDE_PETSC(MatSetValuesBlocked(A, count, block_rows.data(), count, block_rows.data(), K.data(), ADD_VALUES));
  });
  // + (I − P): the constrained directions keep a unit diagonal, as in the shell.
  const std::vector<double> P = projection_blocks(model);
  std::vector<double> complement(static_cast<std::size_t>(d) * d);
  for (VertexId v = 0; v < n; ++v) {
    for (int i = 0; i < d * d; ++i)
      complement[i] = (i % (d + 1) == 0 ? 1.0 : 0.0) - P[static_cast<std::size_t>(v) * d * d + i];
    const PetscInt row = v;
    SNEDE_PETSC(MatSetValuesBlocked(A, 1, &row, 1, &row, complement.data(), ADD_VALUES));
  }
  SNEDE_PETSC(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  if (model.operator_scale() != 1) SNEDE_PETSC(MatScale(A, model.operator_scale()));
}

void set_rigid_body_near_null_space(const Model& model, Mat A) {
  const std::vector<double>& points = model.body().mesh().points();
  VecHandle coordinates;
  SNEDE_PETSC(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(points.size()), coordinates.out()));
  SNEDE_PETSC(VecSetBlockSize(coordinates, model.dim()));
  set_vec_values(coordinates, points);
  MatNullSpace rigid = nullptr;
  SNEDE_PETSC(MatNullSpaceCreateRigidBody(coordinates, &rigid));
  const PetscErrorCode set = MatSetNearNullSpace(A, rigid);
  MatNullSpaceDestroy(&rigid);  // A holds its own reference
  SNEDE_PETSC(set);
}

void tangent_diagonal(const Model& model, Vec u, Vec diagonal) {
  const int d = model.dim(), n = (d + 1) * d;
  std::vector<double> values(model.body().n_dofs(), 0.0);
  {
    ReadView x(u);
    for_each_projected_element_matrix(model, x.span(), [&](std::span<const VertexId> vertices, std::span<const double> K) {
      for (int row = 0; row < n; ++row)
        values[static_cast<std::size_t>(vertices[row / d]) * d + row % d] += K[static_cast<std::size_t>(row) * n + row];
    });
  }
  const std::vector<double> P = projection_blocks(model);
  for (std::size_t dof = 0; dof < values.size(); ++dof) {
    const std::size_t v = dof / d, k = dof % d;
    values[dof] = model.operator_scale() * (values[dof] + 1.0 - P[(v * d + k) * d + k]);
  }
  set_vec_values(diagonal, values);
}

}  // namespace snede
