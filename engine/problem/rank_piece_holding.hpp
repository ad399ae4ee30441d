// The serial check that constraints hold every piece of a body (piece_holding.hpp, §3.3) on a
// body distributed over MPI ranks (issue 52): a piece may lie on several ranks, so each rank
// labels the pieces of its own cells, pieces on two ranks are joined where they share a face
// (agreed by the rank that judges the face: its lowest serial vertex id modulo the ranks), rank 0
// numbers the joined pieces, and each piece's constraint Gram matrix (rigid_motion_gram.hpp) is
// summed over the ranks about one origin. Only the pieces' labels and 6 × 6 matrices travel.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/distributed_mesh.hpp"
#include "problem/piece_holding.hpp"
#include "problem/constraints.hpp"

namespace snede {

// The whole body's pieces as this rank sees them, and those the constraints do not hold.
struct RankPieces {
  std::vector<int> cell_piece;     // per live cell of the part, in mesh.cell_ids() order
  int n_pieces = 0;                // over all ranks, numbered 0..n_pieces−1 alike on every rank
  std::vector<LoosePiece> loose;   // the same on every rank (first_cell: no_id)
  std::vector<std::int64_t> lowest_vertex;  // per piece: its lowest serial vertex id
};

// Collective: the pieces, and which of them some rigid motion leaves free (a membrane: fewer
// than 6 constrained components). `constraints` are the part's local vertices' (owned and ghosts).
RankPieces pieces_on_ranks(const DistributedMesh& part, const Constraints& constraints);

// Collective: throws the same std::invalid_argument on every rank (the serial message) when
// some piece is loose.
void require_held_on_ranks(const DistributedMesh& part, const Constraints& constraints);

}  // namespace snede
