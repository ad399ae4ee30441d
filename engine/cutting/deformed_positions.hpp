// Where the vertices of a tetrahedral mesh are in the deformed configuration, x = X + u: the
// scalpel acts on the body as the user sees it (§3.2), while the mesh is edited in its
// reference configuration.
#pragma once

#include <array>

#include "cutting/sweep_triangle.hpp"
#include "mesh/mesh.hpp"

namespace snede {

class DeformedPositions {
 public:
  // u: 3 numbers per mesh point (the rows of mesh.points()), or null for an undeformed mesh.
  // The view is only valid until the next mesh change.
  DeformedPositions(const Mesh& mesh, const double* u) : mesh_(mesh), u_(u) {}
  Point3 operator()(VertexId v) const {
    const std::span<const double> X = mesh_.point(v);
    if (!u_) return {X[0], X[1], X[2]};
    const double* u = u_ + 3 * static_cast<std::size_t>(v);
    return {X[0] + u[0], X[1] + u[1], X[2] + u[2]};
  }
  std::array<Point3, 4> corners(const Simplex& tet) const {
    return {(*this)(tet.vertex(0)), (*this)(tet.vertex(1)), (*this)(tet.vertex(2)), (*this)(tet.vertex(3))};
  }
  const Mesh& mesh() const { return mesh_; }

 private:
  const Mesh& mesh_;
  const double* u_;
};

}  // namespace snede
