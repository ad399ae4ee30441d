// The four materials (§4.1) with the parameters the kernel tests use, and their names.
#pragma once

#include <type_traits>
#include <variant>
#include <vector>

#include "fem/material.hpp"

namespace snede::testing {

inline std::vector<Material> all_materials() {
  return {LinearElastic(3e3, 0.3), StVenantKirchhoff(3e3, 0.3), NeoHookean(3e3, 0.45), VerondaWestmann(3e3, 0.3, 2.0)};
}

inline const char* name_of(const Material& material) {
  return std::visit([](const auto& m) { return std::decay_t<decltype(m)>::name; }, material);
}

}  // namespace snede::testing
