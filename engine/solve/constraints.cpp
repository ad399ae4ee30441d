#include "solve/constraints.hpp"

#include <bit>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/Dense>

#include "mesh/traversal.hpp"

namespace snede {

void Constraints::check_vertex(VertexId v) const {
  if (v < 0 || v >= n_points())
    throw std::invalid_argument("vertex " + std::to_string(v) + " does not exist (there are " +
                                std::to_string(n_points()) + " points)");
}

void Constraints::fix(std::span<const VertexId> vertices, std::span<const double> values) {
  if (!values.empty() && values.size() != vertices.size() * dim_)
    throw std::invalid_argument("fix: values must be (n_vertices, " + std::to_string(dim_) + ")");
  // A vertex listed twice must not be given two different displacements (the last would win
  // silently). Checked before anything changes.
  std::unordered_map<VertexId, std::size_t> first_listed;
  for (std::size_t i = 0; i < vertices.size() && !values.empty(); ++i) {
    const auto [it, first] = first_listed.try_emplace(vertices[i], i);
    if (!first && !std::equal(values.begin() + i * dim_, values.begin() + (i + 1) * dim_,
                              values.begin() + it->second * dim_))
      throw std::invalid_argument("fix: vertex " + std::to_string(vertices[i]) + " is listed twice (entries " +
                                  std::to_string(it->second) + " and " + std::to_string(i) +
                                  ") with different values");
  }
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    check_vertex(vertices[i]);
    VertexConstraint& c = vertices_[vertices[i]];
    c = VertexConstraint{ConstraintKind::fixed, {0, 0, 0}, {0, 0, 0}};
    for (int k = 0; k < dim_ && !values.empty(); ++k) {
      if (!std::isfinite(values[i * dim_ + k]))
        throw std::invalid_argument("fix: non-finite value for vertex " + std::to_string(vertices[i]));
      c.anchor[k] = values[i * dim_ + k];
    }
  }
}

void Constraints::slide(std::span<const VertexId> vertices, std::span<const double> direction,
                        std::span<const double> u) {
  if (direction.size() != static_cast<std::size_t>(dim_))
    throw std::invalid_argument("slide: direction must have " + std::to_string(dim_) + " components");
  double norm = 0;
  for (double x : direction) norm += x * x;
  norm = std::sqrt(norm);
  if (!(norm > 0 && std::isfinite(norm))) throw std::invalid_argument("slide: direction must be non-zero and finite");
  for (VertexId v : vertices) {
    check_vertex(v);
    VertexConstraint& c = vertices_[v];
    c = VertexConstraint{ConstraintKind::slide, {0, 0, 0}, {0, 0, 0}};
    for (int k = 0; k < dim_; ++k) {
      c.direction[k] = direction[k] / norm;
      c.anchor[k] = u[static_cast<std::size_t>(v) * dim_ + k];
    }
  }
}

std::uint64_t Constraints::projection_fingerprint() const {
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over kinds and directions
  auto mix = [&](std::uint64_t x) {
    for (int byte = 0; byte < 8; ++byte) {
      hash ^= (x >> (8 * byte)) & 0xffu;
      hash *= 1099511628211ull;
    }
  };
  for (const VertexConstraint& c : vertices_) {
    mix(static_cast<std::uint64_t>(c.kind));
    if (c.kind == ConstraintKind::slide)
      for (double x : c.direction) mix(std::bit_cast<std::uint64_t>(x));
  }
  return hash;
}

void Constraints::assign(VertexId v, const VertexConstraint& c) {
  check_vertex(v);
  vertices_[v] = c;
}

void Constraints::release(std::span<const VertexId> vertices) {
  for (VertexId v : vertices) {
    check_vertex(v);
    vertices_[v] = VertexConstraint{};
  }
}

std::size_t Constraints::n_constrained() const {
  std::size_t n = 0;
  for (const auto& c : vertices_) n += c.kind == ConstraintKind::fixed || c.kind == ConstraintKind::slide;
  return n;
}

std::size_t Constraints::constrained_components(VertexId v) const {
  const ConstraintKind kind = vertices_[v].kind;
  return kind == ConstraintKind::fixed ? dim_ : kind == ConstraintKind::slide ? dim_ - 1 : 0;
}

std::size_t Constraints::n_constrained_components() const {
  std::size_t n = 0;
  for (VertexId v = 0; v < n_points(); ++v) n += constrained_components(v);
  return n;
}

void Constraints::project(std::span<double> v) const {
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const VertexConstraint& c = vertices_[i];
    double* x = v.data() + i * dim_;
    if (c.kind == ConstraintKind::fixed || c.kind == ConstraintKind::absent) {
      for (int k = 0; k < dim_; ++k) x[k] = 0;
    } else if (c.kind == ConstraintKind::slide) {
      double along = 0;
      for (int k = 0; k < dim_; ++k) along += x[k] * c.direction[k];
      for (int k = 0; k < dim_; ++k) x[k] = along * c.direction[k];
    }
  }
}

namespace {

// (I − P) x for one vertex's dim numbers, into out (which may be x).
void complement_of(const VertexConstraint& c, int dim, const double* x, double* out) {
  if (c.kind == ConstraintKind::free) {
    std::fill_n(out, dim, 0.0);
  } else if (c.kind == ConstraintKind::slide) {
    double along = 0;
    for (int k = 0; k < dim; ++k) along += x[k] * c.direction[k];
    for (int k = 0; k < dim; ++k) out[k] = x[k] - along * c.direction[k];
  } else {  // fixed or absent: P = 0
    std::copy_n(x, dim, out);
  }
}

}  // namespace

void Constraints::projection_block(VertexId v, std::span<double> block) const {
  check_vertex(v);
  // Column j of P is e_j − (I − P) e_j.
  std::array<double, 3> unit{}, complement{};
  for (int j = 0; j < dim_; ++j) {
    unit.fill(0.0);
    unit[j] = 1.0;
    complement_of(vertices_[v], dim_, unit.data(), complement.data());
    for (int i = 0; i < dim_; ++i) block[static_cast<std::size_t>(i * dim_ + j)] = unit[i] - complement[i];
  }
}

void Constraints::add_complement(std::span<const double> v, std::span<double> out, double scale) const {
  std::array<double, 3> complement{};
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    if (vertices_[i].kind == ConstraintKind::free) continue;
    complement_of(vertices_[i], dim_, v.data() + i * dim_, complement.data());
    for (int k = 0; k < dim_; ++k) out[i * dim_ + k] += scale * complement[k];
  }
}

void Constraints::project_complement(std::span<double> v) const {
  for (std::size_t i = 0; i < vertices_.size(); ++i) complement_of(vertices_[i], dim_, v.data() + i * dim_, v.data() + i * dim_);
}

void Constraints::enforce(std::span<double> u) const {
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const VertexConstraint& c = vertices_[i];
    double* x = u.data() + i * dim_;
    if (c.kind == ConstraintKind::fixed || c.kind == ConstraintKind::absent) {
      for (int k = 0; k < dim_; ++k) x[k] = c.anchor[k];
    } else if (c.kind == ConstraintKind::slide) {
      double along = 0;
      for (int k = 0; k < dim_; ++k) along += (x[k] - c.anchor[k]) * c.direction[k];
      for (int k = 0; k < dim_; ++k) x[k] = c.anchor[k] + along * c.direction[k];
    }
  }
}

void Constraints::inherit(VertexId v, const VertexParents& parents) {
  if (v >= n_points()) resize(v + 1);
  VertexConstraint inherited;
  const bool all_fixed = std::all_of(parents.vertex.begin(), parents.vertex.end(), [&](VertexId p) {
    return vertices_[p].kind == ConstraintKind::fixed;
  });
  if (parents.count() == 1) {
    inherited = vertices_[parents.vertex[0]];
  } else if (parents.count() > 1 && all_fixed) {
    inherited.kind = ConstraintKind::fixed;
    for (std::size_t i = 0; i < parents.count(); ++i)
      for (int k = 0; k < dim_; ++k) inherited.anchor[k] += parents.weight[i] * vertices_[parents.vertex[i]].anchor[k];
  }
  vertices_[v] = inherited;
}

void Constraints::remove(VertexId v) {
  if (v >= n_points()) resize(v + 1);
  vertices_[v] = VertexConstraint{ConstraintKind::absent, {0, 0, 0}, {0, 0, 0}};
}

void PieceHolding::label_pieces() {
  const Connectivity& c = mesh_.connectivity();
  const auto [label, pieces] = connected_components(c);
  vertex_piece_.assign(mesh_.n_points(), -1);
  hinge_pieces_.clear();
  piece_cells_.assign(pieces, 0);
  piece_first_cell_.assign(pieces, no_id);
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    const int piece = label[e];
    if (piece_cells_[piece]++ == 0) piece_first_cell_[piece] = e;
    for (VertexId v : c.element(e).simplex.vertices()) {
      if (vertex_piece_[v] < 0) vertex_piece_[v] = piece;
      else if (vertex_piece_[v] != piece) hinge_pieces_.emplace_back(v, piece);
    }
  }
  std::sort(hinge_pieces_.begin(), hinge_pieces_.end());
  hinge_pieces_.erase(std::unique(hinge_pieces_.begin(), hinge_pieces_.end()), hinge_pieces_.end());
  labelled_revision_ = c.topology_revision();
  labelled_ = true;
}

namespace {

// The rigid motions' values at x (relative to the piece's origin), (dim × n_motions) row-major
// into `rows`: translations, then rotations, u = a + ω × x = a − [x]× ω (3D) or a + ω (−y, x) (2D).
void rigid_motions_at(std::span<const double> x, int dim, std::span<double> rows) {
  const int n = dim == 3 ? 6 : 3;
  std::fill(rows.begin(), rows.end(), 0.0);
  for (int k = 0; k < dim; ++k) rows[k * n + k] = 1;
  if (dim == 2) {
    rows[0 * n + 2] = -x[1];
    rows[1 * n + 2] = x[0];
    return;
  }
  // −[x]× in columns 3–5: (x × ω)_i = ε_ijk x_j ω_k, negated.
  rows[0 * n + 4] = x[2], rows[0 * n + 5] = -x[1];
  rows[1 * n + 3] = -x[2], rows[1 * n + 5] = x[0];
  rows[2 * n + 3] = x[1], rows[2 * n + 4] = -x[0];
}

// A piece's constraint rows on its rigid motions, accumulated as the Gram matrix Σ Rᵀ(I − P)R.
struct RigidMotionGram {
  Eigen::MatrixXd gram;
  double span = 0;  // largest |x − origin| over its constrained vertices: the rotations' scale
  std::size_t components = 0;

  // The rank of the rows: rotations scaled by 1/span so that every entry is O(1); the
  // eigenvalues of a direction the rows do not constrain are then rounding, O(1e-16) relative,
  // and 1e-10 leaves six orders of margin (it counts as a hinge a set of vertices off a line by
  // less than 1e-5 of their span, which holds the piece no better numerically).
  std::size_t rank() const {
    if (components == 0) return 0;
    const int n = static_cast<int>(gram.rows());
    Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
    if (span > 0) scale.tail(n / 2).setConstant(1 / span);
    const Eigen::MatrixXd scaled = scale.asDiagonal() * gram * scale.asDiagonal();
    const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
    const double largest = eigenvalues.maxCoeff();
    return static_cast<std::size_t>((eigenvalues.array() > 1e-10 * largest).count());
  }
};

}  // namespace

std::vector<LoosePiece> PieceHolding::loose_pieces(const Constraints& constraints) {
  if (!labelled_ || labelled_revision_ != mesh_.connectivity().topology_revision()) label_pieces();
  const int pieces = static_cast<int>(piece_cells_.size());
  const int dim = constraints.dim(), n_motions = dim == 3 ? 6 : 3;
  std::vector<RigidMotionGram> grams(pieces, RigidMotionGram{Eigen::MatrixXd::Zero(n_motions, n_motions)});
  std::vector<double> block(static_cast<std::size_t>(dim * dim)), rows(static_cast<std::size_t>(dim * n_motions));
  Eigen::MatrixXd complement(dim, dim);
  const VertexId n = std::min(constraints.n_points(), static_cast<VertexId>(vertex_piece_.size()));
  auto add = [&](VertexId v, int piece) {
    const std::size_t components = constraints.constrained_components(v);
    if (components == 0) return;
    RigidMotionGram& g = grams[piece];
    const auto origin = mesh_.point(mesh_.connectivity().element(piece_first_cell_[piece]).simplex.vertices()[0]);
    std::array<double, 3> x{0, 0, 0};
    for (int k = 0; k < dim; ++k) x[k] = mesh_.point(v)[k] - origin[k];
    g.span = std::max(g.span, std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]));
    g.components += components;
    rigid_motions_at(x, dim, rows);
    constraints.projection_block(v, block);
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j) complement(i, j) = (i == j) - block[static_cast<std::size_t>(i * dim + j)];
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> R(rows.data(), dim,
                                                                                                      n_motions);
    g.gram += R.transpose() * complement * R;
  };
  for (VertexId v = 0; v < n; ++v)
    if (vertex_piece_[v] >= 0) add(v, vertex_piece_[v]);
  for (const auto& [v, piece] : hinge_pieces_)
    if (v < n) add(v, piece);
  // A membrane has no bending stiffness: tension holds it, not the rank of its supports (a
  // sheet hung from a straight rod is a membrane scene), so it keeps the count.
  const bool by_count = mesh_.is_surface();
  std::vector<LoosePiece> loose;
  for (int piece = 0; piece < pieces; ++piece) {
    const std::size_t stopped = grams[piece].rank();
    if ((by_count ? grams[piece].components : stopped) < static_cast<std::size_t>(n_motions))
      loose.push_back({piece, pieces, piece_cells_[piece], piece_first_cell_[piece], grams[piece].components, stopped,
                       static_cast<std::size_t>(n_motions)});
  }
  return loose;
}

void PieceHolding::require_held(const Constraints& constraints) {
  const std::vector<LoosePiece> loose = loose_pieces(constraints);
  if (loose.empty()) return;
  const LoosePiece& first = loose.front();
  const std::string which =
      first.pieces == 1 ? "it is one piece of " + std::to_string(first.cells) + " cells with "
                        : "piece " + std::to_string(first.piece + 1) + " of " + std::to_string(first.pieces) + " (" +
                              std::to_string(first.cells) + " cells, vertex " +
                              std::to_string(mesh_.connectivity().element(first.first_cell).simplex.vertices()[0]) +
                              " among them) has ";
  std::string message = "the body is not held: " + which + std::to_string(first.constrained_components) +
                        " constrained displacement components, which stop " +
                        std::to_string(first.rigid_motions_stopped) + " of its " +
                        std::to_string(first.rigid_motions) +
                        " rigid motions (3 in 2D, 6 in 3D: vertices on one line leave a solid free to turn " +
                        "about it; a membrane needs 6 constrained components)";
  if (first.pieces == 1)
    throw std::invalid_argument(message + "; fix some of its vertices with body.fix");
  message += "; " + std::to_string(loose.size()) + " of the " + std::to_string(first.pieces) + " pieces " +
             (loose.size() == 1 ? "is" : "are") + " not held. A static solve needs every piece held (a cut can " +
             "free one): fix some vertices of each with body.fix, or call body.fix_free_pieces() to fix each on " +
             "one of its cells where it is now (TetrahedralCutter(fix_free_pieces=True) does this while cutting)";
  throw std::invalid_argument(message);
}

}  // namespace snede
