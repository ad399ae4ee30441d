#include "mesh/element_quality.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace snede {
namespace {

template <int D>
using Corners = Eigen::Matrix<double, D + 1, D, Eigen::RowMajor>;

template <int D>
Eigen::Map<const Corners<D>> corners_of(std::span<const double> corners) {
  if (corners.size() != static_cast<std::size_t>((D + 1) * D))
    throw std::invalid_argument("element_quality: expected " + std::to_string((D + 1) * D) + " coordinates");
  return Eigen::Map<const Corners<D>>(corners.data());
}

template <int D>
double signed_volume_of(const Corners<D>& x) {
  Eigen::Matrix<double, D, D> edges;
  for (int i = 0; i < D; ++i) edges.row(i) = x.row(i + 1) - x.row(0);
  return edges.determinant() / (D == 2 ? 2.0 : 6.0);
}

template <int D>
double longest_edge_of(const Corners<D>& x) {
  double longest = 0;
  for (int i = 0; i <= D; ++i)
    for (int j = i + 1; j <= D; ++j) longest = std::max(longest, (x.row(i) - x.row(j)).norm());
  return longest;
}

// Measure of the facet opposite corner i: length of an edge in 2D, area of a triangle in 3D.
template <int D>
double facet_measure(const Corners<D>& x, int i) {
  int other[D];
  for (int j = 0, k = 0; j <= D; ++j)
    if (j != i) other[k++] = j;
  if constexpr (D == 2) {
    return (x.row(other[0]) - x.row(other[1])).norm();
  } else {
    const Eigen::Vector3d a = x.row(other[1]) - x.row(other[0]);
    const Eigen::Vector3d b = x.row(other[2]) - x.row(other[0]);
    return 0.5 * a.cross(b).norm();
  }
}

// Dihedral angle at each edge (i, j) of tetrahedron_edges: the angle between the two faces
// containing it, measured from the components of the other two corners orthogonal to the edge.
std::array<double, 6> dihedral_angles_of(const Corners<3>& x) {
  std::array<double, 6> angles{};
  for (int e = 0; e < 6; ++e) {
    const auto [i, j] = tetrahedron_edges[e];
    int k = 0;
    while (k == i || k == j) ++k;
    const int l = 6 - i - j - k;
    const Eigen::Vector3d edge = (x.row(j) - x.row(i)).normalized();
    Eigen::Vector3d u = x.row(k) - x.row(i), w = x.row(l) - x.row(i);
    u -= u.dot(edge) * edge;
    w -= w.dot(edge) * edge;
    angles[e] = std::atan2(u.cross(w).norm(), u.dot(w));
  }
  return angles;
}

template <int D>
ElementQuality quality_of(const Corners<D>& x) {
  ElementQuality q;
  q.volume = signed_volume_of<D>(x);
  double min_height = std::numeric_limits<double>::infinity(), facets = 0;
  for (int i = 0; i <= D; ++i) {
    const double facet = facet_measure<D>(x, i);
    min_height = std::min(min_height, D * std::abs(q.volume) / facet);
    facets += facet;
  }
  q.aspect_ratio = min_height / longest_edge_of<D>(x);
  q.inscribed_diameter = 2 * D * std::abs(q.volume) / facets;
  q.min_dihedral = std::numbers::pi;
  q.max_dihedral = 0;
  if constexpr (D == 2) {
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d a = x.row((i + 1) % 3) - x.row(i), b = x.row((i + 2) % 3) - x.row(i);
      const double angle = std::atan2(std::abs(a.x() * b.y() - a.y() * b.x()), a.dot(b));
      q.min_dihedral = std::min(q.min_dihedral, angle);
      q.max_dihedral = std::max(q.max_dihedral, angle);
    }
  } else {
    const std::array<double, 6> angles = dihedral_angles_of(x);
    q.min_dihedral = *std::min_element(angles.begin(), angles.end());
    q.max_dihedral = *std::max_element(angles.begin(), angles.end());
  }
  return q;
}

template <class F>
auto dispatch(int dim, std::span<const double> corners, F&& f) {
  if (dim == 2) return f(Corners<2>(corners_of<2>(corners)));
  if (dim == 3) return f(Corners<3>(corners_of<3>(corners)));
  throw std::invalid_argument("element_quality: dimension must be 2 or 3, got " + std::to_string(dim));
}

}  // namespace

double signed_volume(int dim, std::span<const double> corners) {
  return dispatch(dim, corners, [](const auto& x) {
    return signed_volume_of<std::decay_t<decltype(x)>::ColsAtCompileTime>(x);
  });
}

double longest_edge(int dim, std::span<const double> corners) {
  return dispatch(dim, corners, [](const auto& x) {
    return longest_edge_of<std::decay_t<decltype(x)>::ColsAtCompileTime>(x);
  });
}

ElementQuality element_quality(int dim, std::span<const double> corners) {
  return dispatch(dim, corners, [](const auto& x) {
    return quality_of<std::decay_t<decltype(x)>::ColsAtCompileTime>(x);
  });
}

std::array<double, 6> dihedral_angles(std::span<const double> corners) {
  return dihedral_angles_of(Corners<3>(corners_of<3>(corners)));
}

std::array<double, 6> flattened_triangle(std::span<const double> corners) {
  if (corners.size() != 9) throw std::invalid_argument("flattened_triangle: expected 9 coordinates");
  const Eigen::Vector3d a(corners[0], corners[1], corners[2]);
  const Eigen::Vector3d ab = Eigen::Vector3d(corners[3], corners[4], corners[5]) - a;
  const Eigen::Vector3d ac = Eigen::Vector3d(corners[6], corners[7], corners[8]) - a;
  const double length = ab.norm();
  const Eigen::Vector3d e1 = length > 0 ? Eigen::Vector3d(ab / length) : Eigen::Vector3d::UnitX();
  const double along = ac.dot(e1);
  const double across = (ac - along * e1).norm();  // ≥ 0: the image is counter-clockwise
  return {0.0, 0.0, length, 0.0, along, across};
}

double cell_measure(int cell_dim, int space_dim, std::span<const double> corners) {
  if (cell_dim == space_dim) return signed_volume(cell_dim, corners);
  return signed_volume(2, flattened_triangle(corners));
}

double cell_longest_edge(int cell_dim, int space_dim, std::span<const double> corners) {
  return cell_dim == space_dim ? longest_edge(cell_dim, corners) : longest_edge(2, flattened_triangle(corners));
}

double corner_extent(int space_dim, std::span<const double> corners) {
  double extent = 0;
  for (std::size_t i = 0; i < corners.size(); ++i)
    extent = std::max(extent, std::abs(corners[i] - corners[i % space_dim]));
  return extent;
}

bool has_zero_volume(int cell_dim, int space_dim, std::span<const double> corners) {
  constexpr double tolerance = 64 * std::numeric_limits<double>::epsilon();
  // Decided on the corners relative to the first one, divided by a power of two near their
  // extent: the same doubles scaled exactly, so the decision is the same at every scale and
  // neither L^d nor the measure overflows for coordinates of 1e300.
  std::vector<double> x(corners.begin(), corners.end());
  const double extent = corner_extent(space_dim, corners);
  if (extent > 0 && std::isfinite(extent)) {
    int exponent = 0;
    std::frexp(extent, &exponent);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::ldexp(x[i] - corners[i % space_dim], -exponent);
  }
  const double scale = std::pow(cell_longest_edge(cell_dim, space_dim, x), cell_dim);
  return !(std::abs(cell_measure(cell_dim, space_dim, x)) > tolerance * scale);
}

}  // namespace snede
