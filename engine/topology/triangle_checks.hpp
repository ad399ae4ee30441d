// Checks shared by the triangle-mesh edits that retriangulate a small region — the
// quadrilateral of an edge flip (§5.2.2, Figure 5.9), the star of a removed vertex (§5.3.1,
// Figure 5.10) — on 2D meshes and on surfaces (triangles in 3D).
#pragma once

#include <array>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

// Twice the vector area of triangle (a, b, c) of a surface, (b − a) × (c − a) (floating point).
std::array<double, 3> doubled_vector_area(const Mesh& mesh, VertexId a, VertexId b, VertexId c);

// "(a, b)", "(a, b, c)": vertex lists in refusal reasons.
std::string vertex_list(std::initializer_list<VertexId> vertices);

// The plane in which a retriangulation decides orientation, containment and the empty-circle
// criterion. In 2D it is the mesh's own plane and every decision is exact. On a surface it is
// the plane normal to the vector area of the region's boundary polygon (the same for every
// triangulation of the polygon, so old and new triangles are judged against one normal); the
// polygon's vertices are projected onto it in floating point and the signs of the projected
// points are exact. A new triangle whose projection is clockwise — its normal points against
// the region's — would fold the surface over; near-perpendicular cases are decided only as
// well as the projection is rounded (the one floating-point decision of these edits).
class RetriangulationPlane {
 public:
  // polygon: the region's boundary vertices in the orientation of the region's triangles.
  RetriangulationPlane(const Mesh& mesh, std::span<const VertexId> polygon);

  // False on a surface whose polygon has no vector area (no plane to project onto).
  bool has_normal() const { return has_normal_; }
  // Why triangle (a, b, c), in this orientation, cannot be a cell of the retriangulation —
  // clockwise or degenerate in the plane, or on a surface collinear in 3D — or "" if it can.
  std::string triangle_problem(VertexId a, VertexId b, VertexId c) const;
  // True if q lies in the closed triangle (a, b, c), counter-clockwise in the plane.
  bool closed_triangle_contains(VertexId a, VertexId b, VertexId c, VertexId q) const;
  // True if q lies strictly inside the circumcircle of (a, b, c), counter-clockwise in the plane.
  bool in_circumcircle(VertexId a, VertexId b, VertexId c, VertexId q) const;

 private:
  const double* in_plane(VertexId v) const;

  const Mesh& mesh_;
  bool has_normal_ = true;
  std::unordered_map<VertexId, std::array<double, 2>> projected_;  // surfaces only
};

}  // namespace snede
