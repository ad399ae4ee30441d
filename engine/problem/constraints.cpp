#include "problem/constraints.hpp"

#include <bit>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

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

}  // namespace snede
