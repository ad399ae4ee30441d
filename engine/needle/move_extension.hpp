// A needle's move carried into the tissue around it (issue 50). Moving the needle moves its
// sticking nodes (§6.7) and nothing else, so on thin cells along the shaft a move of a fraction
// of h_ref inverts their neighbours, and a solve cannot start from an inverted state: the move
// was halved until it did not. Carrying the move along a few rings of vertices around the
// sticking nodes, by weights that fall smoothly from 1 on them to 0 beyond the rings, starts
// the solve from a state where the shaft's neighbourhood travels with the needle. Only the
// start of the solve changes; its solution (to the solver's tolerance), and so the stick-slip
// path, does not.
#pragma once

#include <span>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"
#include "problem/constraints.hpp"

namespace snede {

// The weights of the vertices within `rings` edges of `moved` that may move (free or sliding
// vertices off the boundary): 1 − ring / (rings + 1) at first, then `sweeps` Jacobi sweeps of
// the edge-graph average with `moved` held at 1 and every other vertex at 0 (constrained ones,
// boundary ones, those beyond the rings): a discrete harmonic extension, as far as the sweeps
// go. Vertices whose weight is 0 are left out.
std::vector<std::pair<VertexId, double>> move_extension_weights(const Mesh& mesh, const Constraints& constraints,
                                                                std::span<const VertexId> moved, int rings,
                                                                int sweeps);

}  // namespace snede
