// The serial check that constraints hold every piece of a body (piece_holding.hpp, §3.3) on a
// body distributed over MPI ranks (issue 52): a piece may lie on several ranks, so each rank
// labels the pieces of its own cells, pieces on two ranks are joined where they share a face
// (agreed by the rank that judges the face: its lowest serial vertex id modulo the ranks), rank 0
// numbers the joined pieces, and each piece's constraint Gram matrix (rigid_motion_gram.hpp) is
// summed over the ranks about one origin. Only the pieces' labels and 6 × 6 matrices travel.
#pragma once

#include "mesh/distributed_mesh.hpp"
#include "problem/constraints.hpp"

namespace snede {

// Collective: throws the same std::invalid_argument on every rank (the serial message) when
// some piece's constraints leave it a rigid motion (a membrane: fewer than 6 constrained
// components). `constraints` are the part's local vertices' (owned and ghosts).
void require_held_on_ranks(const DistributedMesh& part, const Constraints& constraints);

}  // namespace snede
