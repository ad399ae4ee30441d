#include "problem/tangent_assembly.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <numeric>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "problem/projected_stiffness.hpp"
#include "problem/vertex_neighbours.hpp"

namespace snede {
namespace {

// Vertices per cell: dim + 1 for volume meshes, 3 for membranes (triangles in 3D), each with
// dim displacement components.
int corners_per_cell(const Model& model) { return model.body().mesh().cell_dim() + 1; }

// Every vertex's block of the model's P (projected_stiffness.hpp).
std::vector<double> projection_blocks(const Model& model) {
  return projection_blocks(model.constraints(), model.body().mesh().n_points());
}

// The live elements with a corner v for which marked[v] holds.
std::vector<ElementId> elements_with_a_corner(const Connectivity& c, const std::vector<bool>& marked) {
  std::vector<ElementId> found;
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    const std::span<const VertexId> corners = c.element(e).simplex.vertices();
    if (std::any_of(corners.begin(), corners.end(), [&](VertexId v) { return marked[v]; })) found.push_back(e);
  }
  return found;
}

}  // namespace

AssembledTangent::AssembledTangent(const Model& model, MatrixFormat format, MembraneTangent membranes)
    : membranes_(membranes),
      format_(format),
      revision_(model.body().mesh().connectivity().revision()),
      topology_revision_(model.body().mesh().connectivity().topology_revision()) {
  find_neighbours(model);
  make_matrix(model.dim());
}

void AssembledTangent::find_neighbours(const Model& model) {
  const Mesh& mesh = model.body().mesh();
  // A smoothed formulation's vertex patch joins every pair of its vertex's neighbours: blocks
  // for every vertex within two edges, their ranks found per patch (patch_block_ranks).
  patches_ = model.body().formulation() != Formulation::p1;
  VertexNeighbours found = vertex_neighbours(mesh.connectivity(), mesh.n_points(), corners_per_cell(model), patches_);
  neighbour_start_ = std::move(found.start);
  neighbours_ = std::move(found.neighbours);
  block_rank_ = std::move(found.block_rank);
  self_rank_ = std::move(found.self_rank);
}

void AssembledTangent::follow_neighbours(const Model& model, const AssembledTangent& earlier,
                                         const std::vector<bool>& touched) {
  const Connectivity& c = model.body().mesh().connectivity();
  const int corners = corners_per_cell(model);
  const std::size_t n = touched.size();
  // The touched vertices' neighbours come from the elements around them, all of which have a
  // touched corner; every other vertex has the elements, and so the neighbours, it had.
  const std::vector<ElementId> reached = elements_with_a_corner(c, touched);
  std::vector<std::size_t> star_start(n + 1, 0);
  for (ElementId e : reached)
    for (VertexId v : c.element(e).simplex.vertices())
      if (touched[v]) ++star_start[v + 1];
  std::partial_sum(star_start.begin(), star_start.end(), star_start.begin());
  std::vector<ElementId> star(star_start.back());
  std::vector<std::size_t> next(star_start.begin(), star_start.end() - 1);
  for (ElementId e : reached)
    for (VertexId v : c.element(e).simplex.vertices())
      if (touched[v]) star[next[v]++] = e;

  neighbour_start_.assign(n + 1, 0);
  neighbours_.clear();
  neighbours_.reserve(earlier.neighbours_.size() + (star.size() + n - earlier.self_rank_.size()) * corners);
  self_rank_.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    const std::size_t first = neighbours_.size();
    if (touched[v]) {
      neighbours_.push_back(static_cast<VertexId>(v));
      for (std::size_t s = star_start[v]; s < star_start[v + 1]; ++s)
        for (VertexId w : c.element(star[s]).simplex.vertices()) neighbours_.push_back(w);
      const auto row = neighbours_.begin() + static_cast<std::ptrdiff_t>(first);
      std::sort(row, neighbours_.end());
      neighbours_.erase(std::unique(row, neighbours_.end()), neighbours_.end());
      self_rank_[v] = static_cast<std::int32_t>(std::lower_bound(row, neighbours_.end(), static_cast<VertexId>(v)) - row);
    } else {
      neighbours_.insert(neighbours_.end(), earlier.neighbours_.begin() + static_cast<std::ptrdiff_t>(earlier.neighbour_start_[v]),
                         earlier.neighbours_.begin() + static_cast<std::ptrdiff_t>(earlier.neighbour_start_[v + 1]));
      self_rank_[v] = earlier.self_rank_[v];
    }
    neighbour_start_[v + 1] = neighbours_.size();
  }
  // An element without a touched corner is one the earlier mesh had, under the same id, with the
  // same ranks; the reached ones are looked up in their corners' rows.
  block_rank_.assign(static_cast<std::size_t>(c.element_capacity()) * corners * corners, 0);
  std::copy_n(earlier.block_rank_.begin(), std::min(earlier.block_rank_.size(), block_rank_.size()), block_rank_.begin());
  for (ElementId e : reached) {
    // In the corner order of the element matrices (all_vertex_stars, add_entries).
    const auto vertices = c.element(e).simplex.oriented_vertices();
    std::int32_t* ranks = block_rank_.data() + static_cast<std::size_t>(e) * corners * corners;
    for (int a = 0; a < corners; ++a) {
      const auto row = neighbours_.begin() + static_cast<std::ptrdiff_t>(neighbour_start_[vertices[a]]);
      const auto row_end = neighbours_.begin() + static_cast<std::ptrdiff_t>(neighbour_start_[vertices[a] + 1]);
      for (int b = 0; b < corners; ++b)
        ranks[a * corners + b] = static_cast<std::int32_t>(std::lower_bound(row, row_end, vertices[b]) - row);
    }
  }
}

void AssembledTangent::make_matrix(int d) {
  const std::size_t n = self_rank_.size();
  auto neighbours = [&](std::size_t v) {
    return std::span<const VertexId>(neighbours_.data() + neighbour_start_[v], neighbour_start_[v + 1] - neighbour_start_[v]);
  };
  // Each row's columns are sorted, so that an element block (a, b) lies at a's row start plus
  // b's rank among a's neighbours (assemble()). Neither format inserts the structure row by row:
  // that (MatSeqAIJSetPreallocationCSR) took two thirds of this constructor's time (8.5 → 2.7 ms
  // at 24k tetrahedra, event SnedeTangentSparsity).
  const PetscInt rows = static_cast<PetscInt>(n) * d;
  if (format_ == MatrixFormat::baij) {
    // A d × d block per pair of neighbours: the vertex CSR as it is, its columns copied in
    // (PETSc 3.18 takes no block CSR arrays of its own, MatCreateSeqBAIJWithArrays: block size 1).
    std::vector<PetscInt> blocks_per_row(n), block_columns(neighbours_.begin(), neighbours_.end());
    for (std::size_t v = 0; v < n; ++v) blocks_per_row[v] = static_cast<PetscInt>(neighbour_start_[v + 1] - neighbour_start_[v]);
    SNEDE_PETSC(MatCreate(PETSC_COMM_SELF, A_.out()));
    SNEDE_PETSC(MatSetSizes(A_, rows, rows, rows, rows));
    SNEDE_PETSC(MatSetType(A_, MATSEQBAIJ));
    SNEDE_PETSC(MatSeqBAIJSetPreallocation(A_, d, 0, blocks_per_row.data()));
    SNEDE_PETSC(MatSeqBAIJSetColumnIndices(A_, block_columns.data()));
    SNEDE_PETSC(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY));
    SNEDE_PETSC(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY));
  } else {
    // Scalar rows: (row 3a + i, column 3b + j) lies at row_start[3a + i] + 3·rank(a, b) + j.
    auto csr = std::make_unique<CsrArrays>();
    csr->row_start.resize(static_cast<std::size_t>(rows) + 1);
    csr->columns.resize(neighbours_.size() * d * d);
    std::size_t at = 0;
    for (std::size_t v = 0; v < n; ++v)
      for (int i = 0; i < d; ++i) {
        csr->row_start[v * d + i] = static_cast<PetscInt>(at);
        for (VertexId w : neighbours(v))
          for (int j = 0; j < d; ++j) csr->columns[at++] = static_cast<PetscInt>(w) * d + j;
      }
    csr->row_start.back() = static_cast<PetscInt>(at);
    csr->values.assign(at, 0.0);
    A_ = matrix_owning(std::move(csr), rows, rows);
    SNEDE_PETSC(MatSetBlockSize(A_, d));
  }
  SNEDE_PETSC(MatSetOption(A_, MAT_SYMMETRIC, PETSC_TRUE));
  SNEDE_PETSC(MatSetOption(A_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
}

const std::int32_t* AssembledTangent::patch_block_ranks(std::span<const VertexId> vertices,
                                                        std::vector<std::int32_t>& ranks) const {
  // Both lists are sorted: one merge walk per row instead of a search per block.
  const std::size_t count = vertices.size();
  ranks.resize(count * count);
  for (std::size_t a = 0; a < count; ++a) {
    const std::size_t start = neighbour_start_[vertices[a]], end = neighbour_start_[vertices[a] + 1];
    std::size_t k = start;
    for (std::size_t b = 0; b < count; ++b) {
      while (k < end && neighbours_[k] < vertices[b]) ++k;
      if (k == end || neighbours_[k] != vertices[b])
        throw std::logic_error("a strain patch joins vertices more than two edges apart");
      ranks[a * count + b] = static_cast<std::int32_t>(k - start);
    }
  }
  return ranks.data();
}

bool AssembledTangent::matches(const Model& model) const {
  return model.body().mesh().connectivity().revision() == revision_;
}

bool AssembledTangent::follow_moved_vertices(const Model& model) {
  const Connectivity& c = model.body().mesh().connectivity();
  if (c.topology_revision() != topology_revision_) return false;
  revision_ = c.revision();
  return true;
}

void AssembledTangent::assemble(const Model& model, Vec u) {
  if (!matches(model))
    throw std::logic_error("the assembled tangent was made for another mesh: the mesh changed since");
  std::vector<double> P = projection_blocks(model);
  {
    const CsrView A(A_);  // given back before assembling
    const int d = model.dim();
    std::fill(A.value, A.value + static_cast<std::size_t>(A.start[A.rows]) * (A.blocked ? d * d : 1), 0.0);
    add_entries(model, u, A, P);
  }
  SNEDE_PETSC(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY));
  record_fill(model, std::move(P));
}

void AssembledTangent::record_fill(const Model& model, std::vector<double> projections) {
  filled_ = true;
  filled_scale_ = model.operator_scale();
  filled_constraint_stiffness_ = model.constraint_stiffness();
  filled_projections_ = std::move(projections);
}

AssembledTangent::AssembledTangent(const Model& model, const AssembledTangent& earlier, const EditFootprint& edits, Vec u)
    : membranes_(earlier.membranes_),
      format_(earlier.format_),
      revision_(model.body().mesh().connectivity().revision()),
      topology_revision_(model.body().mesh().connectivity().topology_revision()) {
  if (!earlier.can_follow_edits(model) || (u && !earlier.values_can_follow_edits(model)))
    throw std::logic_error("this assembled tangent cannot follow the edits");
  const std::size_t n = static_cast<std::size_t>(model.body().mesh().n_points());
  std::vector<bool> touched(n, false);
  for (VertexId v : edits.vertices())
    if (static_cast<std::size_t>(v) < n) touched[v] = true;
  for (std::size_t v = earlier.self_rank_.size(); v < n; ++v) touched[v] = true;  // added since
  follow_neighbours(model, earlier, touched);
  make_matrix(model.dim());
  if (u) take_values(model, earlier, std::move(touched), u);
}

bool AssembledTangent::can_follow_edits(const Model& model) const {
  return !patches_ && static_cast<std::size_t>(model.body().mesh().n_points()) >= self_rank_.size();
}

bool AssembledTangent::values_can_follow_edits(const Model& model) const {
  return can_follow_edits(model) && filled_ && filled_scale_ == model.operator_scale();
}

void AssembledTangent::take_values(const Model& model, const AssembledTangent& earlier, std::vector<bool> fresh, Vec u) {
  const int d = model.dim(), dd = d * d;
  const std::size_t n = self_rank_.size(), n_earlier = earlier.self_rank_.size();
  std::vector<double> P = projection_blocks(model);
  // Fresh: the vertices the edits touched or added (given), and those whose constraints changed.
  std::vector<bool> constraint_changed(n, false);
  for (std::size_t v = 0; v < n_earlier; ++v) {
    constraint_changed[v] = !std::equal(P.begin() + v * dd, P.begin() + (v + 1) * dd,
                                        earlier.filled_projections_.begin() + v * dd);
    fresh[v] = fresh[v] || constraint_changed[v];
  }
  const Connectivity& c = model.body().mesh().connectivity();
  if (model.body().mesh().is_surface() && membranes_ == MembraneTangent::positive_part) {
    // A membrane element's positive part mixes all its blocks: a corner's new projection
    // changes the element's every block.
    for (ElementId e : elements_with_a_corner(c, constraint_changed))
      for (VertexId v : c.element(e).simplex.vertices()) fresh[v] = true;
  }
  const double s = model.operator_scale();
  const std::vector<double> complement = complement_blocks(P, d);
  const double stiffness_change = model.constraint_stiffness() - earlier.filled_constraint_stiffness_;
  {
    const CsrView from(earlier.A_);
    const CsrView to(A_);
    // Values per block row (BAIJ) or per scalar row (AIJ, d rows per vertex).
    const std::size_t rows_per_vertex = to.blocked ? 1 : d, entries_per_column = to.blocked ? dd : d;
    const std::size_t column_stride = to.blocked ? 1 : d;  // a vertex's columns in a row's column list
    for (std::size_t v = 0; v < n; ++v)
      for (std::size_t r = v * rows_per_vertex; r < (v + 1) * rows_per_vertex; ++r) {
        const std::size_t length = to.start[r + 1] - to.start[r];
        PetscScalar* row = to.value + to.start[r] * (to.blocked ? dd : 1);
        const std::size_t entries = length * (to.blocked ? dd : 1);
        if (fresh[v]) {
          std::fill_n(row, entries, 0.0);
          continue;
        }
        // An untouched vertex's row has the columns it had (follow_neighbours).
        std::copy_n(from.value + from.start[r] * (to.blocked ? dd : 1), entries, row);
        for (std::size_t k = 0; k < length / column_stride; ++k)
          if (fresh[to.column[to.start[r] + k * column_stride] / column_stride])
            std::fill_n(row + k * entries_per_column, entries_per_column, 0.0);
      }
    // c (I − P) of the untouched rows, for the c of now (it follows the cells' mean size).
    for (std::size_t v = 0; v < n && stiffness_change != 0; ++v) {
      if (fresh[v]) continue;
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) {
          const double change = s * stiffness_change * complement[v * dd + i * d + j];
          if (change == 0) continue;
          if (to.blocked)
            to.value[(static_cast<std::size_t>(to.start[v]) + self_rank_[v]) * dd + j * d + i] += change;
          else
            to.value[to.start[v * d + i] + static_cast<std::size_t>(d) * self_rank_[v] + j] += change;
        }
    }
    // Every element with a fresh corner adds its blocks that have a fresh row or column.
    const std::vector<ElementId> reached = elements_with_a_corner(c, fresh);
    add_entries(model, u, to, P, &fresh, &reached);
  }
  SNEDE_PETSC(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY));
  record_fill(model, std::move(P));
}

void AssembledTangent::add_entries(const Model& model, Vec u, const CsrView& A, const std::vector<double>& P,
                                   const std::vector<bool>* fresh, const std::vector<ElementId>* only) const {
  const int d = model.dim();
  std::vector<double> complement = complement_blocks(P, d);
  for (double& x : complement) x *= model.constraint_stiffness();  // c (I − P)
  const bool membrane = model.body().mesh().is_surface() && membranes_ == MembraneTangent::positive_part;
  MembranePositivePart positive_part;
  const double s = model.operator_scale();
  ReadView x(u);
  std::vector<std::int32_t> patch_ranks;
  // The dimension known at compile time, so that the block loops unroll: 7.3 → 5.9 ms per
  // assembly at 24k tetrahedra (BAIJ; AIJ 6.9 → 5.9), of which the element matrices take 2.1.
  auto add_all = [&](auto dimension) {
    constexpr int D = decltype(dimension)::value;
    // Adds s times the D × D block at `K` (rows `stride` apart) into vertex v's block of its
    // rank-th neighbour.
    auto add_block = [&](std::size_t v, std::int32_t rank, const double* K, std::size_t stride) {
      if (A.blocked) {
        PetscScalar* block = A.value + (static_cast<std::size_t>(A.start[v]) + rank) * D * D;
        for (int i = 0; i < D; ++i)
          for (int j = 0; j < D; ++j) block[j * D + i] += s * K[i * stride + j];  // column by column
        return;
      }
      for (int i = 0; i < D; ++i) {
        PetscScalar* row = A.value + A.start[v * D + i] + static_cast<std::size_t>(D) * rank;
        for (int j = 0; j < D; ++j) row[j] += s * K[i * stride + j];
      }
    };
    for_each_projected_element_matrix(model.body(), x.span(), P, [&](ElementId e, std::span<const VertexId> vertices,
                                                                  std::span<const double> element_matrix) {
      const std::span<const double> K = membrane ? positive_part(element_matrix) : element_matrix;
      const int corners = static_cast<int>(vertices.size());
      const std::size_t n = static_cast<std::size_t>(corners) * D;
      const std::int32_t* ranks = patches_ ? patch_block_ranks(vertices, patch_ranks)
                                           : block_rank_.data() + static_cast<std::size_t>(e) * corners * corners;
      for (int a = 0; a < corners; ++a)
        for (int b = 0; b < corners; ++b)
          if (!fresh || (*fresh)[vertices[a]] || (*fresh)[vertices[b]])
            add_block(vertices[a], ranks[a * corners + b], K.data() + (a * n + b) * D, n);
    }, only);
    // + c (I − P): the constrained directions' stiffness, as in the shell.
    for (std::size_t v = 0; v < self_rank_.size(); ++v)
      if (!fresh || (*fresh)[v]) add_block(v, self_rank_[v], complement.data() + v * D * D, D);
  };
  if (d == 3) {
    add_all(std::integral_constant<int, 3>{});
  } else {
    add_all(std::integral_constant<int, 2>{});
  }
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
  const int d = model.dim();
  const std::vector<double> P = projection_blocks(model);
  std::vector<double> values(model.body().n_dofs(), 0.0);
  {
    ReadView x(u);
    for_each_projected_element_matrix(model.body(), x.span(), P, [&](ElementId, std::span<const VertexId> vertices,
                                                                  std::span<const double> K) {
      const int n = static_cast<int>(vertices.size()) * d;
      for (int row = 0; row < n; ++row)
        values[static_cast<std::size_t>(vertices[row / d]) * d + row % d] += K[static_cast<std::size_t>(row) * n + row];
    });
  }
  const std::vector<double> complement = complement_blocks(P, d);
  const double c = model.constraint_stiffness();
  for (std::size_t dof = 0; dof < values.size(); ++dof) {
    const std::size_t v = dof / d, k = dof % d;
    values[dof] = model.operator_scale() * (values[dof] + c * complement[(v * d + k) * d + k]);
  }
  set_vec_values(diagonal, values);
}

}  // namespace snede
