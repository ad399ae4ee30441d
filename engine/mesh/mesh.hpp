// A simplicial mesh: vertex coordinates plus the §7 connectivity. Cells are triangles or
// tetrahedra (cell_dim 2 or 3) whose points live in space_dim ≥ cell_dim coordinates: a
// triangle mesh in 2D, a tetrahedral mesh in 3D, or a triangulated surface in 3D (§5.3).
//
// Vertex ids index the coordinate rows (§7.4: vertex v's coordinates are at
// space_dim·v … space_dim·v + space_dim − 1). Vertices have a lifecycle: added with
// barycentric parents, moved in the reference configuration, removed once no cell uses them.
// A removed vertex's id is freed and reused by a later addition; its row stays (n_points()
// counts rows, n_live_points() the vertices in use). Each of these is a vertex event that
// watchers receive with the next change (or at once, for a move or a removal).
#pragma once

#include <array>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "mesh/connectivity.hpp"
#include "mesh/element_quality.hpp"

namespace snede {

// validate() found a broken invariant; the message names it.
class InvalidMesh : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Mesh {
 public:
  // points: (n_points, space_dim) row-major; cells: (n_cells, cell_dim + 1) row-major.
  // Throws std::invalid_argument naming the offending index for non-finite coordinates,
  // out-of-range or repeated vertex ids, zero-volume (zero-area) cells and non-manifold or
  // overlapping cells. Volume cells of negative orientation are re-oriented (two vertices
  // swapped); a surface is oriented consistently, component by component, following its
  // lowest-numbered triangle (a non-orientable surface is refused).
  Mesh(int cell_dim, int space_dim, std::vector<double> points, std::span<const std::int64_t> cells);
  // A volume mesh: cell_dim = space_dim = dim.
  Mesh(int dim, std::vector<double> points, std::span<const std::int64_t> cells)
      : Mesh(dim, dim, std::move(points), cells) {}

  int cell_dim() const { return connectivity_.dim(); }
  int space_dim() const { return space_dim_; }
  // The coordinate dimension (block size of nodal fields); equals cell_dim() unless a surface.
  int dim() const { return space_dim_; }
  bool is_surface() const { return cell_dim() < space_dim_; }
  VertexId n_points() const { return static_cast<VertexId>(points_.size() / space_dim_); }
  VertexId n_live_points() const { return n_points() - static_cast<VertexId>(free_vertices_.size()); }
  bool is_vertex(VertexId v) const { return v >= 0 && v < n_points() && alive_[v]; }
  std::size_t n_cells() const { return connectivity_.n_elements(); }
  std::size_t n_reoriented() const { return n_reoriented_; }
  const std::vector<double>& points() const { return points_; }
  std::span<const double> point(VertexId v) const {
    return {points_.data() + static_cast<std::size_t>(v) * space_dim_, static_cast<std::size_t>(space_dim_)};
  }
  const Connectivity& connectivity() const { return connectivity_; }
  Connectivity& connectivity() { return connectivity_; }

  // Live cells as (n_cells, cell_dim + 1) positively oriented vertex lists, in element-id
  // order, and the element id of each row.
  std::vector<VertexId> cells() const;
  std::vector<ElementId> cell_ids() const;
  // Corner coordinates of element e: (cell_dim + 1, space_dim), positively oriented.
  std::vector<double> corners(ElementId e) const;
  // Volume (area for triangles, in 2D or on a surface): signed for volume meshes, positive
  // for surface triangles.
  double measure(ElementId e) const;
  std::vector<ElementQuality> quality() const;
  // Boundary faces as (n_faces, cell_dim) vertex lists oriented like their faces (outward
  // normal in 3D, counter-clockwise around the body in 2D), sorted by simplex. On a surface,
  // the boundary edges (rims and cut lips).
  std::vector<VertexId> boundary_faces() const;

  // The face whose vertex set is `vertices` (either orientation: both faces of a pair are
  // found). O(n) scan per call batch.
  std::vector<FaceId> find_faces(const std::vector<VertexId>& face_vertices) const;

  // The weighted sum of the parents' coordinates (space_dim numbers): bit for bit where
  // add_vertex and move_vertex would put a vertex with these parents, so an edit can test
  // the new position exactly before making it. Throws like add_vertex for bad parents.
  std::vector<double> position(const VertexParents& parents) const { return interpolated("position", parents); }
  // Adds a vertex at the weighted sum of its parents' coordinates (reusing a removed id if
  // there is one) and records the parents. Throws std::invalid_argument for a parent that is
  // not a live vertex or weights that are not barycentric.
  VertexId add_vertex(const VertexParents& parents);
  // The parents v was added with; empty for a vertex given at construction.
  VertexParents parents(VertexId v) const;
  // Moves v in the reference configuration to the weighted sum of `parents` (which may
  // include v itself, evaluated before the move); fields are interpolated the same way.
  void move_vertex(VertexId v, const VertexParents& parents);
  // Moves v to explicit coordinates (space_dim numbers); fields at v are kept.
  void move_vertex(VertexId v, std::span<const double> x);
  // Removes a vertex no cell uses any more; throws std::invalid_argument otherwise.
  void remove_vertex(VertexId v);

  // Checks (7.1)–(7.5), vertex incidences, that every cell uses live vertices, and positive
  // volume (non-zero area on a surface) of every cell. Throws InvalidMesh with the first
  // violation.
  void validate() const;

 private:
  void check_live_vertex(const char* operation, VertexId v) const;
  std::vector<double> interpolated(const char* operation, const VertexParents& parents) const;

  int space_dim_;
  std::vector<double> points_;
  std::vector<std::uint8_t> alive_;
  std::vector<VertexId> free_vertices_;
  Connectivity connectivity_;
  std::size_t n_reoriented_ = 0;
  std::unordered_map<VertexId, VertexParents> parents_;  // of vertices added after construction
};

}  // namespace snede
