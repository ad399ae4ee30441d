// How an ElasticBody turns its vertices' displacements into strains (issue 35). Both keep
// vertex-only unknowns, so cuts, bisection, needles and the preconditioners see the same
// degrees of freedom:
//   p1        one constant F per linear simplex (§2.3), the thesis's element;
//   smoothed  strains averaged over patches of simplices (smoothed FEM, Liu et al.): on
//             tetrahedra the material's shear part on edge patches (ES-FEM) and its bulk part
//             on vertex patches (NS-FEM), which does not lock as ν → ½; on plane-stress
//             triangles, which do not lock, the whole energy on edge patches (fem/strain_patches.hpp).
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <string_view>

namespace snede {

enum class Formulation { p1, smoothed };

inline constexpr std::array<std::string_view, 2> formulation_names{"p1", "smoothed"};

inline std::string_view name_of(Formulation formulation) {
  return formulation_names[static_cast<std::size_t>(formulation)];
}

// Throws std::invalid_argument naming the value and the known names.
inline Formulation parse_formulation(std::string_view name) {
  for (std::size_t k = 0; k < formulation_names.size(); ++k)
    if (formulation_names[k] == name) return static_cast<Formulation>(k);
  std::string known;
  for (std::string_view n : formulation_names) known += (known.empty() ? "" : ", ") + std::string(n);
  throw std::invalid_argument("unknown formulation '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace snede
