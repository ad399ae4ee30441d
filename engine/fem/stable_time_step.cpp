#include "fem/stable_time_step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>
#include <vector>

#include "mesh/element_quality.hpp"

namespace snede {
namespace {

// Modulus of the dilatational wave: λ + 2μ in 3D, E/(1 − ν²) = 4μ(λ+μ)/(λ+2μ) in plane stress.
// Veronda-Westmann's small-strain stiffness has λ' = λ + 2μ(2γ − 1) (§4.3.4, see
// veronda_westmann.hpp): with λ alone its default step was up to 3× too large at γ = 50.
double dilatational_modulus(const Material& material, int dim) {
  Lame lame = std::visit([](const auto& m) { return m.lame; }, material);
  if (const auto* vw = std::get_if<VerondaWestmann>(&material)) lame.lambda += 2 * lame.mu * (2 * vw->gamma - 1);
  // The ratio first: μ(λ + μ) underflows for E = 1e-200 Pa and overflows for E = 1e160 Pa.
  return dim == 3 ? lame.lambda + 2 * lame.mu : 4 * lame.mu * ((lame.lambda + lame.mu) / (lame.lambda + 2 * lame.mu));
}

}  // namespace

// h: with the shortest edge (the h of the text around (2.61)) the estimate exceeded the
// stability limit 2/√λ_max(M⁻¹K) by 1.4–1.8× on structured boxes and gmsh cylinders, so the
// default step would blow up. The inscribed diameter is the element length in 1D and gave
// 0.3–0.98 of the limit on the same meshes (2D and 3D, ν from 0 to 0.49).
// A membrane (§5.3) carries in-plane waves only: each triangle is measured in its own plane,
// and its waves travel at the plane-stress speed.
double cfl_time_step(const Mesh& mesh, const Material& material, double density) {
  double size = std::numeric_limits<double>::infinity();
  for (ElementId e : mesh.cell_ids()) {
    const std::vector<double> corners = mesh.corners(e);
    const ElementQuality quality = mesh.is_surface() ? element_quality(2, flattened_triangle(corners))
                                                     : element_quality(mesh.dim(), corners);
    size = std::min(size, quality.inscribed_diameter);
  }
  const double wave_speed = std::sqrt(dilatational_modulus(material, mesh.cell_dim()) / density);
  return 2 / std::sqrt(3.0) * size / wave_speed;  // (2.61)
}

}  // namespace snede
