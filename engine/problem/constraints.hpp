// Vertex constraints as projections (§3.1, §6.6): a fixed vertex keeps a prescribed
// displacement; a sliding vertex moves along a line through where it was when the
// constraint was set. P is the orthogonal projection onto the allowed motions (0 for fixed,
// t tᵀ for sliding along t, I for free); the constraint reads (I − P)(u − anchor) = 0.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

// absent: a removed vertex, in no element: out of the problem (P = 0, held at zero) but not a
// support (no reaction, not counted as constrained).
enum class ConstraintKind : std::uint8_t { free, fixed, slide, absent };

struct VertexConstraint {
  ConstraintKind kind = ConstraintKind::free;
  std::array<double, 3> anchor{0, 0, 0};     // displacement that (I − P) must keep
  std::array<double, 3> direction{0, 0, 0};  // unit line direction (slide)
};

class Constraints {
 public:
  explicit Constraints(int dim) : dim_(dim) {}
  int dim() const { return dim_; }
  void resize(VertexId n_points) { vertices_.resize(n_points); }
  VertexId n_points() const { return static_cast<VertexId>(vertices_.size()); }
  const VertexConstraint& operator[](VertexId v) const { return vertices_[v]; }

  // values: dim numbers per vertex, or empty for zero displacement.
  void fix(std::span<const VertexId> vertices, std::span<const double> values);
  // Slide along `direction` (dim numbers, normalised here) through the current displacement.
  void slide(std::span<const VertexId> vertices, std::span<const double> direction, std::span<const double> u);
  void release(std::span<const VertexId> vertices);
  // A hash of which vertices are constrained and how (kinds and slide directions, not the
  // anchors): what a preconditioner built from the projections depends on.
  std::uint64_t projection_fingerprint() const;
  // Gives v the constraint `c` as it is (a copy of another mesh's vertex: a multigrid level).
  void assign(VertexId v, const VertexConstraint& c);
  std::size_t n_constrained() const;
  // Number of independent constrained displacement components: of vertex v (dim when fixed,
  // dim − 1 when sliding), and of all vertices.
  std::size_t constrained_components(VertexId v) const;
  std::size_t n_constrained_components() const;

  // v ← P v
  void project(std::span<double> v) const;
  // Vertex v's block of P (dim × dim, row-major) into `block`.
  void projection_block(VertexId v, std::span<double> block) const;
  // v ← (I − P) v
  void project_complement(std::span<double> v) const;
  // out += scale (I − P) v, touching only the constrained vertices' entries.
  void add_complement(std::span<const double> v, std::span<double> out, double scale = 1.0) const;
  // u ← P u + (I − P) anchor: the nearest displacement that satisfies the constraints.
  void enforce(std::span<double> u) const;
  // A new vertex inherits its parents' constraint when they agree (one parent: its
  // constraint; all parents fixed: fixed at the interpolated anchor); otherwise free.
  void inherit(VertexId v, const VertexParents& parents);
  // v was removed from the mesh.
  void remove(VertexId v);

 private:
  void check_vertex(VertexId v) const;
  int dim_;
  std::vector<VertexConstraint> vertices_;
};

}  // namespace snede
