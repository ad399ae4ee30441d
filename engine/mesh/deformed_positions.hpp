// Where the vertices of a mesh are in the deformed configuration, x = X + u: the one place
// the cutters (§3.2, §5.2, §5.3) and the needle (§6.4) read it. Their tools act on the body as
// the user sees it, while the mesh is edited in its reference configuration.
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "core/vec3.hpp"
#include "mesh/mesh.hpp"

namespace snede {

class DeformedPositions {
 public:
  // u: mesh.dim() numbers per mesh point row, or empty for the reference mesh (x = X). A
  // vertex past u's rows (added since u was read) is at its reference point. The view is
  // valid only while u and the mesh's points are.
  DeformedPositions(const Mesh& mesh, std::span<const double> u) : mesh_(mesh), u_(u), dim_(mesh.dim()) {}

  // In 2D the third coordinate is 0.
  Point3 operator()(VertexId v) const {
    const std::span<const double> X = mesh_.point(v);
    const std::size_t row = static_cast<std::size_t>(v) * dim_;
    Point3 x{0, 0, 0};
    if (row + dim_ > u_.size()) {
      for (int k = 0; k < dim_; ++k) x[k] = X[k];
      return x;
    }
    for (int k = 0; k < dim_; ++k) x[k] = X[k] + u_[row + k];
    return x;
  }
  std::array<Point3, 4> corners(const Simplex& tet) const {
    return {(*this)(tet.vertex(0)), (*this)(tet.vertex(1)), (*this)(tet.vertex(2)), (*this)(tet.vertex(3))};
  }
  const Mesh& mesh() const { return mesh_; }

 private:
  const Mesh& mesh_;
  std::span<const double> u_;
  int dim_;
};

// Where vertex v is in the deformed mesh, X_v + u_v (u as for DeformedPositions).
inline Point3 deformed_point(const Mesh& mesh, std::span<const double> u, VertexId v) {
  return DeformedPositions(mesh, u)(v);
}

}  // namespace snede
