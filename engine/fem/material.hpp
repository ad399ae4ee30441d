// The four materials of §4.3 as one value type; the element loop is templated on the
// alternative (std::visit once per mesh loop, never a virtual call per element).
#pragma once

#include <variant>

#include "fem/linear_elastic.hpp"
#include "fem/neo_hookean.hpp"
#include "fem/st_venant_kirchhoff.hpp"
#include "fem/veronda_westmann.hpp"

namespace snede {

using Material = std::variant<LinearElastic, StVenantKirchhoff, NeoHookean, VerondaWestmann>;

// True for the materials whose energy is +∞ for an inverted element (neo-Hookean,
// Veronda-Westmann): a state with an inverted element is then never a solution.
inline bool forbids_inversion(const Material& material) {
  return std::visit([](const auto& m) { return std::decay_t<decltype(m)>::forbids_inversion; }, material);
}

inline double young_modulus(const Material& material) {
  return std::visit([](const auto& m) { return m.lame.mu * (3 * m.lame.lambda + 2 * m.lame.mu) / (m.lame.lambda + m.lame.mu); },
                    material);
}

}  // namespace snede
