// A scalpel sweep triangle Δ_j (§3.2): the surface a line-segment scalpel sweeps between two
// positions, as a triangle in deformed space, and the exact tests the face selection asks of
// it. Which side of Δ a point lies on decides which edges are cut, so the yes/no answers use
// exact orientation predicates; only the crossing parameter along an edge is rounded.
#pragma once

#include <array>
#include <optional>
#include <span>

#include "core/vec3.hpp"

namespace snede {

class SweepTriangle {
 public:
  // corners: 9 numbers, (3, 3) row-major. Throws std::invalid_argument, naming the value,
  // for a non-finite coordinate or three collinear corners (no plane to cut along).
  explicit SweepTriangle(std::span<const double> corners);

  const Point3& corner(int i) const { return corner_[i]; }
  const Point3& normal() const { return normal_; }  // unit normal of the supporting plane
  double offset() const { return offset_; }          // plane: normal · x = offset
  double signed_distance(const Point3& x) const;
  Point3 project(const Point3& x) const;  // orthogonal projection onto the supporting plane

  // Where the segment p→q meets the closed triangle, as the fraction t ∈ [0, 1] along it, or
  // nothing. A segment lying in the triangle's plane does not cross it.
  std::optional<double> crossing(const Point3& p, const Point3& q) const;
  // Whether the closed tetrahedron (4 corners, any orientation) and the closed triangle meet.
  bool meets_tetrahedron(const std::array<Point3, 4>& tet) const;
  // Whether the closed triangle abc meets this one (used to find the first contact with the
  // body's boundary). Coplanar triangles count as meeting when their bounding boxes overlap.
  bool meets_triangle(const Point3& a, const Point3& b, const Point3& c) const;
  // Whether an axis-aligned box [lo, hi] can meet the triangle (its bounding box overlaps).
  bool box_overlaps(const Point3& lo, const Point3& hi) const;

 private:
  std::array<Point3, 3> corner_;
  Point3 normal_{};
  double offset_ = 0;
  Point3 lo_{}, hi_{};
};

}  // namespace snede
