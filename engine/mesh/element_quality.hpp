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

// The edges of a tetrahedron as pairs of corner indices, in the order dihedral_angles uses.
inline constexpr std::array<std::array<int, 2>, 6> tetrahedron_edges{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
// A tetrahedron's dihedral angle (radians) at each of tetrahedron_edges; `corners` (4, 3).
std::array<double, 6> dihedral_angles(std::span<const double> corners);

// A triangle in 3D (surface meshes, §5.3), `corners` (3, 3), laid flat in its own plane: its
// (2, 2)-corner image with positive area, so that the 2D measures above apply to it.
std::array<double, 6> flattened_triangle(std::span<const double> corners);

// A cell of dimension cell_dim with corners (cell_dim + 1, space_dim) in space_dim ≥ cell_dim
// coordinates: its signed volume (area ≥ 0 for a surface triangle) and longest edge.
double cell_measure(int cell_dim, int space_dim, std::span<const double> corners);
double cell_longest_edge(int cell_dim, int space_dim, std::span<const double> corners);
// The largest coordinate difference between the cell's first corner and the others (max norm).
double corner_extent(int space_dim, std::span<const double> corners);
// Whether the cell is degenerate: |V| ≤ 64ε·(longest edge)^cell_dim, a few ulps of its scale,
// so that thin but real cells (aspect ratio 1e-6) are not. The mesh refuses such cells, and
// edits refuse to make them.
bool has_zero_volume(int cell_dim, int space_dim, std::span<const double> corners);

}  // namespace snede
