#include "cutting/triangle_grid.hpp"

#include <algorithm>
#include <cmath>

namespace snede {

void TriangleGrid::build(const Mesh& mesh, const std::function<Point3(VertexId)>& position) {
  const Connectivity& c = mesh.connectivity();
  cells_.clear();
  all_.clear();
  std::vector<std::array<Point3, 3>> corners;
  double total = 0;
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    const Simplex& t = c.element(e).simplex;
    corners.push_back({position(t.vertex(0)), position(t.vertex(1)), position(t.vertex(2))});
    all_.push_back(e);
    for (int k = 0; k < 3; ++k) {
      const Point3 &a = corners.back()[k], &b = corners.back()[(k + 1) % 3];
      total += std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    }
  }
  cell_size_ = all_.empty() || total == 0 ? 1.0 : 2 * total / (3.0 * static_cast<double>(all_.size()));
  for (std::size_t i = 0; i < all_.size(); ++i) {
    Point3 lo = corners[i][0], hi = corners[i][0];
    for (const Point3& x : corners[i])
      for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], x[d]), hi[d] = std::max(hi[d], x[d]);
    const Cell from = cell_of(lo), to = cell_of(hi);
    for (std::int64_t i0 = from[0]; i0 <= to[0]; ++i0)
      for (std::int64_t i1 = from[1]; i1 <= to[1]; ++i1)
        for (std::int64_t i2 = from[2]; i2 <= to[2]; ++i2) cells_[key({i0, i1, i2})].push_back(all_[i]);
  }
}

TriangleGrid::Cell TriangleGrid::cell_of(const Point3& x) const {
  Cell cell{};
  for (int d = 0; d < 3; ++d) cell[d] = static_cast<std::int64_t>(std::floor(std::clamp(x[d] / cell_size_, -1e15, 1e15)));
  return cell;
}

std::uint64_t TriangleGrid::key(const Cell& cell) {
  // 21 bits per axis; distant cells may share a key, which only adds candidates.
  const auto bits = [](std::int64_t i) { return static_cast<std::uint64_t>(i) & ((1u << 21) - 1); };
  return bits(cell[0]) | bits(cell[1]) << 21 | bits(cell[2]) << 42;
}

bool TriangleGrid::collect(const Point3& lo, const Point3& hi, std::vector<ElementId>& found) const {
  const Cell from = cell_of(lo), to = cell_of(hi);
  double count = 1;
  for (int d = 0; d < 3; ++d) count *= static_cast<double>(to[d] - from[d] + 1);
  if (count > static_cast<double>(cells_.size())) return false;
  for (std::int64_t i0 = from[0]; i0 <= to[0]; ++i0)
    for (std::int64_t i1 = from[1]; i1 <= to[1]; ++i1)
      for (std::int64_t i2 = from[2]; i2 <= to[2]; ++i2)
        if (const auto cell = cells_.find(key({i0, i1, i2})); cell != cells_.end())
          found.insert(found.end(), cell->second.begin(), cell->second.end());
  return true;
}

std::vector<ElementId> TriangleGrid::unique(std::vector<ElementId> found) {
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

std::vector<ElementId> TriangleGrid::near(const Point3& lo, const Point3& hi) const {
  std::vector<ElementId> found;
  return collect(lo, hi, found) ? unique(std::move(found)) : all_;
}

std::vector<ElementId> TriangleGrid::near_sweep(const Point3& h0, const Point3& t0, const Point3& h1,
                                                const Point3& t1) const {
  // A bilinear patch lies in the hull of its corners: the sweep cut along the segment into
  // pieces about a cell long, each piece's box.
  const double length = std::max(distance(h0, t0), distance(h1, t1));
  const int pieces = static_cast<int>(std::clamp(std::ceil(length / cell_size_), 1.0, 64.0));
  std::vector<ElementId> found;
  for (int k = 0; k < pieces; ++k) {
    const double s0 = static_cast<double>(k) / pieces, s1 = static_cast<double>(k + 1) / pieces;
    const std::array<Point3, 4> corners{lerp(h0, t0, s0), lerp(h0, t0, s1), lerp(h1, t1, s0), lerp(h1, t1, s1)};
    Point3 lo = corners[0], hi = corners[0];
    for (const Point3& x : corners)
      for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], x[d]), hi[d] = std::max(hi[d], x[d]);
    if (!collect(lo, hi, found)) return all_;
  }
  return unique(std::move(found));
}

}  // namespace snede
