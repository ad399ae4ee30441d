// A rank's part made straight from the cells it was given (issue 52), without DMPlex: for parts
// that are already balanced, as a generator's or a chunked reader's are, the cells stay where
// they are, so the only work is to agree on the vertices between the ranks. One exchange with
// the rank whose range holds each vertex id gives its coordinates and its owner (that rank if
// its own cells use the vertex, else the lowest rank that uses it); a second gives PETSc's
// numbering (owned vertices numbered contiguously in rank order, ghosts carrying their owner's
// number), the same layout DMPlexGetVertexNumbering gives, so DistributedStatic and the
// writers take either part alike. Memory: the given arrays, the part and the exchange's buffers,
// never a DM beside them.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <vector>

#include "mesh/distributed_mesh.hpp"

namespace snede {

// Collective. `given` must already have passed distribute_cells's checks; its arrays are
// consumed. Throws the same std::invalid_argument on every rank when a vertex is in no cell.
DistributedMesh part_as_given(MPI_Comm comm, RankCells given, std::int64_t n_global_vertices,
                              std::int64_t n_global_cells);

// The signed volume (area) of a simplex of a volume mesh, its corners' ids indexing `points`
// (space_dim per point): the parts are made positively oriented, as snede's serial meshes are.
double simplex_orientation(const std::vector<double>& points, int space_dim, const std::int64_t* corners,
                           int n_corners);

}  // namespace snede
