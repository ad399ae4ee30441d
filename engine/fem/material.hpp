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

}  // namespace snede
