// A simplicial mesh: node coordinates plus the §7 connectivity. Vertex ids are indices into
// the coordinate array (§7.4: vertex v's coordinates are at dim·v … dim·v + dim − 1).
#pragma once

#include <array>
#include <stdexcept>
#include <vector>

#include "mesh/connectivity.hpp"
#include "mesh/dissect.hpp"
#include "mesh/element_quality.hpp"

namespace snede {

// validate() found a broken invariant; the message names it.
class InvalidMesh : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Where a vertex added after construction came from: its coordinates (and, in a model, its
// displacement) are the weighted sum of its parents' (a copy: one parent, weight 1; an edge
// midpoint: two parents, weights ½).
struct VertexParents {
  std::array<VertexId, 2> vertex{no_id, no_id};
  std::array<double, 2> weight{0, 0};
  int count = 0;
};

class Mesh {
 public:
  // points: (n_points, dim) row-major; cells: (n_cells, dim + 1) row-major.
  // Throws std::invalid_argument naming the offending index for non-finite coordinates,
  // out-of-range or repeated vertex ids, zero-volume cells and non-manifold or overlapping
  // cells. Negatively oriented cells are re-oriented (two vertices swapped).
  Mesh(int dim, std::vector<double> points, std::span<const std::int64_t> cells);

  int dim() const { return dim_; }
  VertexId n_points() const { return static_cast<VertexId>(points_.size() / dim_); }
  std::size_t n_cells() const { return connectivity_.n_elements(); }
  std::size_t n_reoriented() const { return n_reoriented_; }
  const std::vector<double>& points() const { return points_; }
  const Connectivity& connectivity() const { return connectivity_; }
  Connectivity& connectivity() { return connectivity_; }

  // Live cells as (n_cells, dim + 1) positively oriented vertex lists, in element-id order,
  // and the element id of each row.
  std::vector<VertexId> cells() const;
  std::vector<ElementId> cell_ids() const;
  // Corner coordinates of element e: (dim + 1, dim), positively oriented.
  std::vector<double> corners(ElementId e) const;
  std::vector<ElementQuality> quality() const;
  // Boundary faces as (n_faces, dim) vertex lists oriented like their faces (outward normal
  // in 3D, counter-clockwise around the body in 2D), sorted by simplex.
  std::vector<VertexId> boundary_faces() const;

  // The face whose vertex set is `vertices` (either orientation: the one of the lower
  // element id is not implied; both faces of a pair are found). O(n) scan per call batch.
  std::vector<FaceId> find_faces(const std::vector<VertexId>& face_vertices) const;
  // §7.3 dissect along the given interior faces (given by vertices); new vertices are copies
  // of the originals' coordinates.
  std::vector<SplitVertex> dissect(const std::vector<VertexId>& face_vertices);

  // Adds a vertex at the weighted sum of its parents' coordinates and records the parents.
  VertexId add_vertex(const VertexParents& parents);
  // The parents of v; count = 0 for a vertex given at construction.
  VertexParents parents(VertexId v) const;

  // Checks (7.1)–(7.5), vertex ids against the coordinate array, and positive volume of
  // every element. Throws InvalidMesh with the first violation.
  void validate() const;

 private:
  int dim_;
  std::vector<double> points_;
  Connectivity connectivity_;
  std::size_t n_reoriented_ = 0;
  VertexId n_initial_points_ = 0;
  std::vector<VertexParents> added_parents_;  // for vertices n_initial_points_, ...
};

}  // namespace snede
