// Refinement along a segment (§6.5 refine-around generalised from a point to a needle's
// shaft, §6.9 and Figure 6.14): bisect until every element that comes within `radius` of the
// segment a–b has edges no longer than h. All splits are one mesh change (one ChangeBatch), so
// watchers reissue sizes once per call.
#pragma once

#include <cstddef>
#include <span>

#include "topology/bisection.hpp"

namespace snede {

// a, b: (dim,) reference coordinates (a = b refines around a point, like refine_around, but
// with a radius). "Comes within radius" is the exact distance between the segment and the
// closed element (segment_distance.hpp), so only elements the tube meets are split for their
// size; neighbours are split only as conformity needs. Returns the number of elements split. Throws std::invalid_argument for h not
// positive and finite, radius negative or not finite, points of the wrong dimension or not
// finite, h below 1e-12 of a nearby edge length (beyond round-off), or a segment that does not
// come within radius of any element — unless `near_found` is given: it then tells whether any
// element came near (a rank's part of a distributed mesh, which may hold none of the segment).
std::size_t refine_near_segment(Bisection& bisection, std::span<const double> a, std::span<const double> b, double h,
                                double radius, bool* near_found = nullptr);

}  // namespace snede
