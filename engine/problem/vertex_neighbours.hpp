// The block sparsity of an assembled tangent (tangent_assembly.hpp serially,
// distributed_assembly.hpp on ranks): each vertex's neighbours, itself included, in one flat
// array (CSR), and every element block's place among its row's neighbours, made vertex by
// vertex from the elements around each (one small sort per vertex, a scratch array for the
// places) rather than by searching sorted lists.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/connectivity.hpp"

namespace snede {

struct VertexNeighbours {
  std::vector<std::size_t> start;        // per vertex, into neighbours (+ 1 at the end)
  std::vector<VertexId> neighbours;      // per vertex, sorted
  std::vector<std::int32_t> block_rank;  // per element id and block (a, b), corners in all_vertex_stars' order: b's place in a's row
  std::vector<std::int32_t> self_rank;   // per vertex: its own place in its row
};

// For vertices 0..n − 1 of elements of `corners` vertices. two_edges: also every vertex two
// edges away (a smoothed formulation's vertex patches join every pair of a vertex's
// neighbours); block_rank is then left empty (a patch's blocks are found per patch). order:
// each vertex's sort key (PETSc's global numbers on ranks, so that a row's columns come in
// PETSc's order), or empty to sort by id.
VertexNeighbours vertex_neighbours(const Connectivity& c, VertexId n, int corners, bool two_edges,
                                   std::span<const std::int64_t> order = {});

}  // namespace snede
