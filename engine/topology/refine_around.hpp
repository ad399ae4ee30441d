// §6.5 refine-around(x, h): bisect until every element whose closure contains x has edges
// no longer than h (Figures 6.8 and 6.13).
#pragma once

#include <cstddef>
#include <span>

#include "topology/bisection.hpp"

namespace snede {

// x: (dim,). Returns the number of elements split. Throws std::invalid_argument for h not
// positive and finite, h below 1e-12 of the local edge length (beyond round-off), a point
// of the wrong dimension or outside the mesh.
std::size_t refine_around(Bisection& bisection, std::span<const double> x, double h);

}  // namespace snede
