#include "topology/triangle_checks.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/predicates.hpp"
#include "mesh/element_quality.hpp"

namespace snede {

namespace {

using Vector3 = std::array<double, 3>;

Vector3 difference(std::span<const double> x, std::span<const double> y) { return {x[0] - y[0], x[1] - y[1], x[2] - y[2]}; }
Vector3 cross(const Vector3& u, const Vector3& w) {
  return {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
}
double dot(const Vector3& u, const Vector3& w) { return u[0] * w[0] + u[1] * w[1] + u[2] * w[2]; }
Vector3 normalized(const Vector3& u) {
  const double length = std::sqrt(dot(u, u));
  return {u[0] / length, u[1] / length, u[2] / length};
}

}  // namespace

std::array<double, 3> doubled_vector_area(const Mesh& mesh, VertexId a, VertexId b, VertexId c) {
  return cross(difference(mesh.point(b), mesh.point(a)), difference(mesh.point(c), mesh.point(a)));
}

std::string vertex_list(std::initializer_list<VertexId> vertices) {
  std::string text = "(";
  for (VertexId v : vertices) text += (text.size() > 1 ? ", " : "") + std::to_string(v);
  return text + ")";
}

RetriangulationPlane::RetriangulationPlane(const Mesh& mesh, std::span<const VertexId> polygon) : mesh_(mesh) {
  if (!mesh.is_surface()) return;
  // Vector area of the polygon, as a fan from its first vertex (origin-independent).
  const auto origin = mesh.point(polygon[0]);
  Vector3 area{0, 0, 0};
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    const Vector3 side = cross(difference(mesh.point(polygon[i]), origin), difference(mesh.point(polygon[i + 1]), origin));
    for (int k = 0; k < 3; ++k) area[k] += side[k];
  }
  if (!(dot(area, area) > 0)) {
    has_normal_ = false;
    return;
  }
  const Vector3 normal = normalized(area);
  // (first, second, normal) is right-handed, so counter-clockwise in the plane = normal side.
  const auto least = std::min_element(normal.begin(), normal.end(), [](double x, double y) { return std::abs(x) < std::abs(y); });
  Vector3 axis{0, 0, 0};
  axis[least - normal.begin()] = 1;
  const Vector3 first = normalized(cross(normal, axis));
  const Vector3 second = cross(normal, first);
  for (VertexId v : polygon) {
    const Vector3 x = difference(mesh.point(v), origin);
    projected_[v] = {dot(x, first), dot(x, second)};
  }
}

const double* RetriangulationPlane::in_plane(VertexId v) const {
  if (!mesh_.is_surface()) return mesh_.point(v).data();
  const auto found = projected_.find(v);
  if (found == projected_.end())
    throw std::logic_error("RetriangulationPlane: vertex " + std::to_string(v) + " is not on the region's polygon");
  return found->second.data();
}

std::string RetriangulationPlane::triangle_problem(VertexId a, VertexId b, VertexId c) const {
  // Part of a refusal message, built only when one is given.
  const auto triangle = [&] { return "triangle " + vertex_list({a, b, c}); };
  if (mesh_.is_surface() && collinear_3d(mesh_.point(a).data(), mesh_.point(b).data(), mesh_.point(c).data()))
    return triangle() + " would be degenerate (its corners are collinear)";
  // Exactly non-collinear is not enough: a triangle flat to rounding (a flip back onto the
  // edge a bisection split) is one the mesh would refuse at construction, and its children
  // under the next bisection come out inverted or flat.
  std::vector<double> corners;
  for (VertexId v : {a, b, c}) corners.insert(corners.end(), mesh_.point(v).begin(), mesh_.point(v).end());
  if (has_zero_volume(2, mesh_.space_dim(), corners))
    return triangle() + " would be degenerate (its corners are collinear to rounding)";
  const int orientation = orientation_2d(in_plane(a), in_plane(b), in_plane(c));
  if (orientation > 0) return "";
  if (mesh_.is_surface()) return triangle() + " would fold over (its normal points against the region's)";
  return triangle() + (orientation == 0 ? " would be degenerate (its corners are collinear)" : " would be inverted (clockwise)");
}

bool RetriangulationPlane::closed_triangle_contains(VertexId a, VertexId b, VertexId c, VertexId q) const {
  const double *x = in_plane(a), *y = in_plane(b), *z = in_plane(c), *p = in_plane(q);
  return orientation_2d(x, y, p) >= 0 && orientation_2d(y, z, p) >= 0 && orientation_2d(z, x, p) >= 0;
}

bool RetriangulationPlane::in_circumcircle(VertexId a, VertexId b, VertexId c, VertexId q) const {
  return in_circle(in_plane(a), in_plane(b), in_plane(c), in_plane(q)) > 0;
}

}  // namespace snede
