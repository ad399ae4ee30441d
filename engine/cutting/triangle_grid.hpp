// A uniform grid over the triangles of a surface (§5.3.2: the scalpel may touch the surface
// anywhere), so that finding the triangles near the scalpel tests only those whose bounding
// boxes share a cell with the query box, not the whole surface.
#pragma once

#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include "cutting/sweep_triangle.hpp"
#include "mesh/mesh.hpp"

namespace snede {

class TriangleGrid {
 public:
  // Bins every live triangle of `mesh` by the bounding box of its corners at `position(v)`;
  // cells are twice the mean edge length.
  void build(const Mesh& mesh, const std::function<Point3(VertexId)>& position);
  // The triangles whose boxes may meet the box [lo, hi] (each once).
  std::vector<ElementId> near(const Point3& lo, const Point3& hi) const;
  // The triangles whose boxes may meet the surface a segment sweeps moving with constant
  // end velocities from h0→t0 to h1→t1 (each once): far fewer than its box holds when the
  // segment is long and slanted.
  std::vector<ElementId> near_sweep(const Point3& h0, const Point3& t0, const Point3& h1, const Point3& t1) const;

 private:
  // Appends the triangles of the cells the box [lo, hi] covers; false when it covers more
  // cells than hold triangles (then every triangle is a candidate).
  bool collect(const Point3& lo, const Point3& hi, std::vector<ElementId>& found) const;
  static std::vector<ElementId> unique(std::vector<ElementId> found);
  using Cell = std::array<std::int64_t, 3>;
  Cell cell_of(const Point3& x) const;
  static std::uint64_t key(const Cell& cell);

  double cell_size_ = 1;
  std::unordered_map<std::uint64_t, std::vector<ElementId>> cells_;
  std::vector<ElementId> all_;  // for boxes spanning too many cells
};

}  // namespace snede
