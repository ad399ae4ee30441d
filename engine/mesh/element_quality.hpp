// Geometric measures of one simplex: signed volume (area in 2D), aspect ratio (minimum
// height over maximum edge, §3.2.3) and the extreme dihedral angles (interior angles in 2D).
#pragma once

#include <array>
#include <span>

namespace snede {

struct ElementQuality {
  double volume = 0;        // positive for a positively oriented element
  double aspect_ratio = 0;  // min height / max edge: 0.816 for the regular tetrahedron, 0.866 for the regular triangle
  double min_dihedral = 0;  // radians
  double max_dihedral = 0;  // radians
  double inscribed_diameter = 0;  // 2r = 2·dim·|τ| / Σ facet measures: the element's length scale
};

// `corners`: (dim + 1, dim) coordinates, row-major; dim is 2 or 3.
double signed_volume(int dim, std::span<const double> corners);
double longest_edge(int dim, std::span<const double> corners);
ElementQuality element_quality(int dim, std::span<const double> corners);

// A triangle in 3D (surface meshes, §5.3), `corners` (3, 3), laid flat in its own plane: its
// (2, 2)-corner image with positive area, so that the 2D measures above apply to it.
std::array<double, 6> flattened_triangle(std::span<const double> corners);

}  // namespace snede
