#include "topology/orientation_checks.hpp"

#include <array>
#include <sstream>
#include <vector>

#include "core/predicates.hpp"
#include "mesh/element_quality.hpp"

namespace snede {
namespace {

std::array<double, 3> normal(const double* a, const double* b, const double* c) {
  const std::array<double, 3> u{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const std::array<double, 3> v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

}  // namespace

MovedShape shape_with_corner_at(const Mesh& mesh, ElementId e, VertexId corner, std::span<const double> x) {
  const Simplex& simplex = mesh.connectivity().element(e).simplex;
  const auto vertices = simplex.oriented_vertices();
  std::array<const double*, 4> before{}, after{};
  for (int i = 0; i < simplex.count(); ++i) {
    before[i] = mesh.point(vertices[i]).data();
    after[i] = vertices[i] == corner ? x.data() : before[i];
  }
  int sign;
  if (mesh.is_surface()) {
    if (collinear_3d(after[0], after[1], after[2])) return MovedShape::flat;
    const auto n_old = normal(before[0], before[1], before[2]), n_new = normal(after[0], after[1], after[2]);
    sign = n_old[0] * n_new[0] + n_old[1] * n_new[1] + n_old[2] * n_new[2] > 0 ? 1 : -1;
  } else if (mesh.cell_dim() == 2) {
    sign = orientation_2d(after[0], after[1], after[2]);
  } else {
    sign = orientation_3d(after[0], after[1], after[2], after[3]);
  }
  if (sign < 0) return MovedShape::inverted;
  if (sign == 0) return MovedShape::flat;
  // Positive, but perhaps thinner than the mesh accepts (its measure lost in rounding).
  std::vector<double> corners;
  for (int i = 0; i < simplex.count(); ++i) corners.insert(corners.end(), after[i], after[i] + mesh.space_dim());
  return has_zero_volume(mesh.cell_dim(), mesh.space_dim(), corners) ? MovedShape::flat : MovedShape::positive;
}

std::string spoiled_by_move(const Mesh& mesh, std::span<const ElementId> elements, VertexId corner,
                            std::span<const double> x) {
  for (ElementId e : elements) {
    const MovedShape shape = shape_with_corner_at(mesh, e, corner, x);
    if (shape == MovedShape::positive) continue;
    std::ostringstream why;
    why.precision(17);
    why << "element " << e << " " << mesh.connectivity().element(e).simplex.to_string() << " would be "
        << (shape == MovedShape::flat ? "flat" : "inverted") << " with vertex " << corner << " at (";
    for (std::size_t k = 0; k < x.size(); ++k) why << (k ? ", " : "") << x[k];
    why << ")";
    return why.str();
  }
  return {};
}

}  // namespace snede
