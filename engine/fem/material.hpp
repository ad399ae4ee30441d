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

inline double young_modulus(const Lame& lame) { return lame.mu * ((3 * lame.lambda + 2 * lame.mu) / (lame.lambda + lame.mu)); }
inline double poisson_ratio(const Lame& lame) { return lame.lambda / (2 * (lame.lambda + lame.mu)); }

inline double young_modulus(const Material& material) {
  return std::visit([](const auto& m) { return young_modulus(m.lame); }, material);
}

}  // namespace snede
