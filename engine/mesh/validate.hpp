// Checks the invariants (7.1)–(7.5) of the connectivity. Expensive (hash sets over all
// faces): for tests and debugging, and for users who want certainty after their own edits.
#pragma once

#include <optional>
#include <string>

#include "mesh/connectivity.hpp"

namespace snede {

// The first violated invariant, described precisely (which object, which simplexes), or
// nullopt if the connectivity is valid.
std::optional<std::string> find_violation(const Connectivity& c);

}  // namespace snede
