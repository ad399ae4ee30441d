// A mesh partitioned over the ranks of a communicator by PETSc (issue 18): the cells, given
// whole on rank 0 or a part on every rank (issue 52: no rank need hold the whole), are handed to DMPlex, distributed with DMPlexDistribute (its partitioner,
// PTScotch or the default, chosen with -petscpartitioner_type), and each rank's part is held
// in snede's own connectivity, so the same kernels run on the local cells. Cells are not
// overlapped: a cell lives on exactly one rank; a vertex on several ranks' cells is owned by
// one of them (PETSc's point SF decides) and a ghost on the others.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

struct DistributedMesh {
  MPI_Comm comm = MPI_COMM_NULL;
  std::unique_ptr<Mesh> local;                // this rank's cells, local vertex ids 0..n-1
  std::vector<std::int64_t> global_vertex;    // the serial mesh's id of each local vertex
  std::vector<std::uint8_t> owned;            // 1 where this rank owns the local vertex
  // PETSc's vertex numbering: each rank's owned vertices are numbered contiguously, in rank
  // order; a ghost carries its owner's number. A distributed vector's row block of a vertex.
  std::vector<std::int64_t> global_number;
  std::int64_t n_global_vertices = 0;
  std::int64_t n_global_cells = 0;
};

// Collective on `comm`. Rank 0 passes the serial mesh, every vertex used by a cell: triangles
// in 2D, tetrahedra in 3D, or a membrane's surface (triangles in 3D: cell_dim 2, space_dim 3,
// which DMPlex distributes alike); the other ranks pass nullptr. Throws the same
// std::invalid_argument on every rank when rank 0's mesh is missing or has unused vertices (the
// decision is broadcast, so no rank waits for another).
DistributedMesh distribute_mesh(MPI_Comm comm, const Mesh* serial);

// A part of a mesh as a generator or a reader on one rank gives it (issue 52): some of the
// cells, by global vertex ids, and the coordinates of a range of vertices; the ranges follow
// each other in rank order (rank 0 the first ids, ...), so a rank's range starts where the
// previous rank's ends. Every vertex must be in some cell.
struct RankCells {
  int cell_dim = 3;
  int space_dim = 3;
  std::vector<std::int64_t> cells;   // (cell_dim + 1) global vertex ids per cell
  std::vector<double> coordinates;   // space_dim per vertex of this rank's range
};

// Collective: the mesh whose parts every rank gives (consumed). Balanced parts (the largest at
// most 1.2 times the mean) stay as given (part_as_given.hpp); others are balanced by
// DMPlexDistribute (a rank's cells need not stay on it). global_vertex holds the global ids. Throws the same
// std::invalid_argument on every rank when a rank's part is malformed (sizes, dimensions that
// differ between ranks, an id outside 0..n_vertices−1) or a vertex is in no cell.
// keep_as_given: every rank keeps the cells it gives, balanced or not (a cut gathering the
// cells near the scalpel on one rank).
DistributedMesh distribute_cells(MPI_Comm comm, RankCells part, bool keep_as_given = false);

}  // namespace snede
