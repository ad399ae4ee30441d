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

 private:
  using Cell = std::array<std::int64_t, 3>;
  Cell cell_of(const Point3& x) const;
  static std::uint64_t key(const Cell& cell);

  double cell_size_ = 1;
  std::unordered_map<std::uint64_t, std::vector<ElementId>> cells_;
  std::vector<ElementId> all_;  // for boxes spanning too many cells
};

}  // namespace snede
