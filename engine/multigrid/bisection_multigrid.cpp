#include "multigrid/bisection_multigrid.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "mesh/element_quality.hpp"

namespace snede {
namespace {

// Coarse levels aim at halving h: about 2^dim times fewer elements than the next finer level
// (the cut of a uniformly bisected mesh dim depths up); this slack allows local refinement.
constexpr double coarsening_slack = 1.5;
// Relative tolerance of the conformity check (sums of element measures in floating point).
constexpr double measure_tolerance = 1e-10;

double total_measure(const Mesh& mesh) {
  double sum = 0;
  for (ElementId e : mesh.cell_ids()) sum += std::abs(mesh.measure(e));
  return sum;
}

// The measure of the boundary (area in 3D, length in 2D). A cut through the tree that left a
// hanging vertex has faces on one side only inside the body: more boundary than the fine mesh.
double boundary_measure(const Mesh& mesh) {
  const int d = mesh.dim();
  const std::vector<VertexId> faces = mesh.boundary_faces();
  double sum = 0;
  std::vector<double> corners(static_cast<std::size_t>(d) * d);
  for (std::size_t f = 0; f < faces.size(); f += d) {
    for (int i = 0; i < d; ++i) {
      const std::span<const double> x = mesh.point(faces[f + i]);
      std::copy(x.begin(), x.end(), corners.begin() + static_cast<std::ptrdiff_t>(i) * d);
    }
    sum += d == 3 ? std::abs(cell_measure(2, 3, corners)) : std::hypot(corners[2] - corners[0], corners[3] - corners[1]);
  }
  return sum;
}

bool close(double a, double b) { return std::abs(a - b) <= measure_tolerance * std::max(std::abs(a), std::abs(b)); }

std::size_t rigid_modes(int dim) { return dim == 3 ? 6 : 3; }

}  // namespace

struct BisectionMultigrid::Level {
  std::vector<VertexId> vertex;  // this level's vertex i is the fine mesh's vertex[i]
  std::unique_ptr<Mesh> mesh;
  std::unique_ptr<ElasticBody> body;
  std::unique_ptr<Model> model;  // declared last: released first, it watches the mesh
  VecHandle state;               // the fine state injected (the linearisation point)
  MatHandle interpolation;       // to the next finer level
};

BisectionMultigrid::BisectionMultigrid(Model& fine, const RefinementHierarchy& hierarchy, int max_levels)
    : fine_(fine),
      hierarchy_(hierarchy),
      revision_(fine.body().mesh().connectivity().revision()),
      constraints_(fine.constraints().projection_fingerprint()) {
  const Mesh& mesh = fine.body().mesh();
  if (max_levels == 1 || max_levels < 0)
    throw std::invalid_argument("mg needs at least 2 levels (the mesh and a coarser one), got pc_mg_levels " +
                                std::to_string(max_levels));
  if (mesh.is_surface())
    throw std::invalid_argument("preconditioner 'mg' works on volume meshes (triangles in 2D, tetrahedra in 3D), "
                                "not on a surface mesh");
  // Nodes are appended after their parents: one pass gives every depth.
  std::vector<int> depth(hierarchy.n_nodes(), 0);
  for (std::size_t n = 0; n < depth.size(); ++n)
    if (hierarchy.node(static_cast<NodeId>(n)).parent != no_id) depth[n] = depth[hierarchy.node(static_cast<NodeId>(n)).parent] + 1;
  // Every split's midpoint, with the ends of the edge it bisected.
  midpoint_of_.assign(mesh.n_points(), {no_id, no_id});
  for (std::size_t n = 0; n < depth.size(); ++n) {
    const RefinementNode& node = hierarchy.node(static_cast<NodeId>(n));
    if (node.is_leaf()) continue;
    const TaggedSimplex& label = node.label;
    const VertexId midpoint = hierarchy.midpoint(static_cast<NodeId>(n));
    if (midpoint >= 0 && midpoint < mesh.n_points())
      midpoint_of_[midpoint] = {label.refinement_start(), label.refinement_end()};
  }
  // Size of the cut at every depth: the ancestors there of the live elements, and the live
  // elements that are shallower.
  std::vector<char> ancestor(depth.size(), 0);
  int finest = 0;
  std::vector<std::size_t> nodes_at(1, 0), leaves_at(1, 0);
  for (ElementId e : mesh.cell_ids()) {
    const NodeId leaf = hierarchy.node_of(e);
    finest = std::max(finest, depth[leaf]);
    if (static_cast<std::size_t>(finest) >= leaves_at.size()) leaves_at.resize(finest + 1, 0);
    ++leaves_at[depth[leaf]];
    for (NodeId n = leaf; n != no_id && !ancestor[n]; n = hierarchy.node(n).parent) ancestor[n] = 1;
  }
  nodes_at.assign(finest + 1, 0);
  for (std::size_t n = 0; n < depth.size(); ++n)
    if (ancestor[n] && depth[n] <= finest) ++nodes_at[depth[n]];
  auto cut_size = [&](int k) {
    std::size_t size = nodes_at[k];
    for (int j = 0; j < k; ++j) size += leaves_at[j];
    return size;
  };
  // A leaf whose element left the tree (dissected, flipped, collapsed or removed: its element
  // was changed into a new root, or is gone) under an ancestor of live elements makes every
  // level at that ancestor's depth or above overlap the new roots, or cover the removed volume:
  // such levels are not tried (each attempt built a coarse mesh to find that out: 3 ms at
  // 24 576 tetrahedra after a cut, about 20 at 98 304).
  int overlapping_up_to = -1;
  for (std::size_t n = 0; n < depth.size(); ++n) {
    const RefinementNode& node = hierarchy.node(static_cast<NodeId>(n));
    if (!node.is_leaf() || node.element != no_id) continue;
    for (NodeId a = node.parent; a != no_id && depth[a] > overlapping_up_to; a = hierarchy.node(a).parent)
      if (ancestor[a]) {
        overlapping_up_to = depth[a];
        break;
      }
  }
  const double ratio = coarsening_slack / static_cast<double>(1 << mesh.dim());
  std::size_t current = mesh.n_cells();
  std::vector<std::unique_ptr<Level>> finest_first;
  // finest_first.size() + 1 levels so far, the fine one included.
  for (int k = finest - 1; k > overlapping_up_to && (max_levels == 0 || static_cast<int>(finest_first.size()) + 1 < max_levels);
       --k) {
    const std::size_t size = cut_size(k);
    if (size >= current) break;
    if (k > 0 && static_cast<double>(size) > ratio * static_cast<double>(current)) continue;
    std::unique_ptr<Level> level = make_level(k, depth);
    if (!level) break;  // not conforming, or not held by its constraints: the coarsest is the last one
    current = size;
    finest_first.push_back(std::move(level));
  }
  if (finest_first.empty())
    throw std::invalid_argument(
        "preconditioner 'mg' needs a mesh refined by bisection (mesh.refine_uniform or refine_around) whose coarser "
        "levels are conforming meshes held by the constraints; this mesh has " +
        std::to_string(finest) + " bisection level(s) above its coarsest elements and none of them qualifies " +
        "(cuts and flips take elements out of the refinement tree): use 'gamg'");
  if (max_levels > 0 && static_cast<int>(finest_first.size()) + 1 < max_levels)
    throw std::invalid_argument("pc_mg_levels " + std::to_string(max_levels) + ": this mesh's bisection hierarchy " +
                                "gives " + std::to_string(finest_first.size() + 1) + " levels");
  coarse_.assign(std::make_move_iterator(finest_first.rbegin()), std::make_move_iterator(finest_first.rend()));
  for (std::size_t i = 0; i < coarse_.size(); ++i)
    make_interpolation(*coarse_[i], i + 1 < coarse_.size() ? coarse_[i + 1]->vertex : std::vector<VertexId>{});
}

BisectionMultigrid::~BisectionMultigrid() = default;

bool BisectionMultigrid::matches_mesh() const {
  return fine_.body().mesh().connectivity().revision() == revision_;
}

bool BisectionMultigrid::matches() const {
  return matches_mesh() && fine_.constraints().projection_fingerprint() == constraints_;
}

std::vector<std::size_t> BisectionMultigrid::level_unknowns() const {
  std::vector<std::size_t> unknowns;
  for (const auto& level : coarse_) unknowns.push_back(static_cast<std::size_t>(level->model->n_dofs()));
  unknowns.push_back(static_cast<std::size_t>(fine_.n_dofs()));
  return unknowns;
}

std::vector<std::size_t> BisectionMultigrid::level_sizes() const {
  std::vector<std::size_t> cells;
  for (const auto& level : coarse_) cells.push_back(level->mesh->n_cells());
  cells.push_back(fine_.body().mesh().n_cells());
  return cells;
}

std::unique_ptr<BisectionMultigrid::Level> BisectionMultigrid::make_level(int k, const std::vector<int>& depth) const {
  const Mesh& mesh = fine_.body().mesh();
  const int d = mesh.dim();
  std::vector<char> taken(depth.size(), 0);
  std::vector<NodeId> nodes;
  for (ElementId e : mesh.cell_ids()) {
    NodeId n = hierarchy_.node_of(e);
    while (depth[n] > k) n = hierarchy_.node(n).parent;
    if (!taken[n]) {
      taken[n] = 1;
      nodes.push_back(n);
    }
  }
  auto level = std::make_unique<Level>();
  std::vector<VertexId> index(mesh.n_points(), no_id);
  std::vector<std::int64_t> cells;
  cells.reserve(nodes.size() * (d + 1));
  for (NodeId n : nodes)
    for (int i = 0; i <= d; ++i) {
      const VertexId v = hierarchy_.node(n).label.vertex[i];
      if (!mesh.is_vertex(v)) return nullptr;  // an ancestor of a cut: its corner is gone
      if (index[v] == no_id) {
        index[v] = static_cast<VertexId>(level->vertex.size());
        level->vertex.push_back(v);
      }
      cells.push_back(index[v]);
    }
  std::vector<double> points;
  points.reserve(level->vertex.size() * d);
  for (VertexId v : level->vertex) {
    const std::span<const double> x = mesh.point(v);
    points.insert(points.end(), x.begin(), x.end());
  }
  try {
    level->mesh = std::make_unique<Mesh>(d, std::move(points), cells);
  } catch (const std::invalid_argument&) {
    return nullptr;  // overlapping or non-manifold: elements outside the tree overlap their ancestors
  }
  if (!close(total_measure(*level->mesh), total_measure(mesh)) ||
      !close(boundary_measure(*level->mesh), boundary_measure(mesh)))
    return nullptr;
  const ElasticBody& body = fine_.body();
  level->body = std::make_unique<ElasticBody>(*level->mesh, body.material(), body.density(), body.thickness(),
                                              body.formulation());
  level->model = std::make_unique<Model>(*level->body);
  if (!copy_constraints(*level)) return nullptr;
  SNEDE_PETSC(VecDuplicate(level->model->displacement(), level->state.out()));
  return level;
}

bool BisectionMultigrid::copy_constraints(Level& level) const {
  Constraints& constraints = level.model->constraints();
  for (std::size_t i = 0; i < level.vertex.size(); ++i)
    constraints.assign(static_cast<VertexId>(i), fine_.constraints()[level.vertex[i]]);
  return constraints.n_constrained_components() >= rigid_modes(fine_.dim());
}

bool BisectionMultigrid::follow_constraints() {
  for (const auto& level : coarse_)
    if (!copy_constraints(*level)) return false;
  for (std::size_t i = 0; i < coarse_.size(); ++i)
    make_interpolation(*coarse_[i], i + 1 < coarse_.size() ? coarse_[i + 1]->vertex : std::vector<VertexId>{});
  constraints_ = fine_.constraints().projection_fingerprint();
  return true;
}

void BisectionMultigrid::make_interpolation(Level& coarse, const std::vector<VertexId>& fine_vertices) const {
  const Mesh& mesh = fine_.body().mesh();
  const int d = mesh.dim();
  const Constraints& constraints = fine_.constraints();
  std::vector<VertexId> coarse_index(mesh.n_points(), no_id);
  for (std::size_t i = 0; i < coarse.vertex.size(); ++i) coarse_index[coarse.vertex[i]] = static_cast<VertexId>(i);
  // A fine vertex's value is a weighted sum of coarse vertices' values: itself if it is one,
  // else the mean of the ends of the edge it bisected (linear along that edge).
  using Weights = std::vector<std::pair<VertexId, double>>;
  std::vector<Weights> memo(mesh.n_points());
  std::vector<char> done(mesh.n_points(), 0);
  std::function<const Weights&(VertexId)> weights = [&](VertexId v) -> const Weights& {
    if (done[v]) return memo[v];
    Weights w;
    if (coarse_index[v] != no_id) {
      w.emplace_back(coarse_index[v], 1.0);
    } else {
      const auto [a, b] = midpoint_of_[v];
      if (a == no_id)
        throw std::logic_error("mg: fine vertex " + std::to_string(v) +
                               " is neither a coarse vertex nor the midpoint of a bisection");
      for (VertexId end : {a, b})
        for (const auto& [c, x] : weights(end)) {
          auto it = std::find_if(w.begin(), w.end(), [c = c](const auto& p) { return p.first == c; });
          if (it == w.end()) w.emplace_back(c, 0.5 * x);
          else it->second += 0.5 * x;
        }
    }
    done[v] = 1;
    memo[v] = std::move(w);
    return memo[v];
  };
  const bool finest = fine_vertices.empty();
  const auto n_rows = static_cast<PetscInt>(finest ? mesh.n_points() : fine_vertices.size());
  std::vector<PetscInt> nonzeros(static_cast<std::size_t>(n_rows) * d, 0);
  for (PetscInt r = 0; r < n_rows; ++r) {
    const VertexId v = finest ? r : fine_vertices[r];
    if (!mesh.is_vertex(v)) continue;  // a removed vertex: out of the problem, a zero row
    for (int i = 0; i < d; ++i) nonzeros[static_cast<std::size_t>(r) * d + i] = static_cast<PetscInt>(weights(v).size()) * d;
  }
  const auto n_columns = static_cast<PetscInt>(coarse.vertex.size()) * d;
  SNEDE_PETSC(MatCreateSeqAIJ(PETSC_COMM_SELF, n_rows * d, n_columns, 0, nonzeros.data(), coarse.interpolation.out()));
  // Block (v, c) = weight · P_v P_c: the projections of both levels' constraints.
  std::vector<double> Pv(static_cast<std::size_t>(d) * d), Pc(Pv.size()), block(Pv.size());
  std::vector<PetscInt> rows(d), columns(d);
  for (PetscInt r = 0; r < n_rows; ++r) {
    const VertexId v = finest ? r : fine_vertices[r];
    if (!mesh.is_vertex(v)) continue;
    constraints.projection_block(v, Pv);
    for (int i = 0; i < d; ++i) rows[i] = r * d + i;
    for (const auto& [c, w] : weights(v)) {
      constraints.projection_block(coarse.vertex[c], Pc);
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) {
          double sum = 0;
          for (int m = 0; m < d; ++m) sum += Pv[i * d + m] * Pc[m * d + j];
          block[i * d + j] = w * sum;
        }
      for (int j = 0; j < d; ++j) columns[j] = c * d + j;
      SNEDE_PETSC(MatSetValues(coarse.interpolation, d, rows.data(), d, columns.data(), block.data(), INSERT_VALUES));
    }
  }
  SNEDE_PETSC(MatAssemblyBegin(coarse.interpolation, MAT_FINAL_ASSEMBLY));
  SNEDE_PETSC(MatAssemblyEnd(coarse.interpolation, MAT_FINAL_ASSEMBLY));
}

void BisectionMultigrid::configure(PC pc, const SolverOptions& options, const std::vector<double>& smoother_bounds) {
  const auto n = static_cast<PetscInt>(n_levels());
  SNEDE_PETSC(PCSetType(pc, PCMG));
  SNEDE_PETSC(PCMGSetLevels(pc, n, nullptr));
  SNEDE_PETSC(PCMGSetType(pc, PC_MG_MULTIPLICATIVE));
  SNEDE_PETSC(PCMGSetGalerkin(pc, PC_MG_GALERKIN_NONE));  // every level has its own operator
  for (PetscInt l = 1; l < n; ++l) {
    SNEDE_PETSC(PCMGSetInterpolation(pc, l, coarse_[l - 1]->interpolation));
    KSP smoother = nullptr;
    SNEDE_PETSC(PCMGGetSmoother(pc, l, &smoother));
    options.use_for(smoother);
    // The finest level's operator is the PC's own (the fine shell).
    if (l < n - 1)
      SNEDE_PETSC(KSPSetOperators(smoother, coarse_[l]->model->tangent(), coarse_[l]->model->tangent()));
    set_chebyshev_jacobi_smoother(smoother, options,
                                  smoother_bounds.size() == static_cast<std::size_t>(n - 1) ? smoother_bounds[l - 1] : 0.0);
  }
  set_direct_coarse_solve(pc, options);
  KSP coarse = nullptr;
  SNEDE_PETSC(PCMGGetCoarseSolve(pc, &coarse));
  coarsest_matrix_ = std::make_unique<AssembledTangent>(*coarse_[0]->model, MatrixFormat::aij);
  SNEDE_PETSC(KSPSetOperators(coarse, coarse_[0]->model->tangent(), coarsest_matrix_->mat()));
}

bool BisectionMultigrid::prefer_positive_definite() {
  if (coarse_at_rest_) return false;
  coarse_at_rest_ = true;
  return true;
}

void BisectionMultigrid::update(Vec u, Mat) {
  const int d = fine_.dim();
  ReadView fine_state(u);
  for (const auto& level : coarse_) {
    {
      WriteView state(level->state);
      for (std::size_t i = 0; i < level->vertex.size(); ++i)
        for (int k = 0; k < d; ++k)
          state.span()[i * d + k] =
              coarse_at_rest_ ? 0.0 : fine_state.span()[static_cast<std::size_t>(level->vertex[i]) * d + k];
    }
    Model& model = *level->model;
    model.set_linearization_point(level->state);
    model.set_operator_scale(fine_.operator_scale());
    // A new state for the level's smoother (its Chebyshev bounds and Jacobi diagonal).
    SNEDE_PETSC(MatAssemblyBegin(model.tangent(), MAT_FINAL_ASSEMBLY));
    SNEDE_PETSC(MatAssemblyEnd(model.tangent(), MAT_FINAL_ASSEMBLY));
  }
  if (coarsest_matrix_) coarsest_matrix_->assemble(*coarse_[0]->model, coarse_[0]->state);
}

}  // namespace snede
