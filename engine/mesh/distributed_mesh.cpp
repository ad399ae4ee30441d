#include "mesh/distributed_mesh.hpp"

#include <petscdmplex.h>
#include <petscsf.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"
#include "core/rank_agreement.hpp"
#include "mesh/part_as_given.hpp"

#ifdef SNEDE_HAVE_PTSCOTCH
extern "C" void SCOTCH_randomReset(void);  // scotch.h's, which needs SCOTCH_Num's width
#endif

namespace snede {
namespace {

// PETSc keeps an inner duplicate of a communicator while objects on it live and frees it with
// the last one; the next object then duplicates the communicator again, a collective call.
// Python destroys objects when its garbage collector runs, at different times on different
// ranks: one rank would duplicate while another, still holding an object, would not, and both
// would wait for ever. A reference taken at the first distribution, and never given back, keeps
// the duplicate for the life of the process (later calls find it: no communication).
void keep_petsc_communicator(MPI_Comm comm) {
  MPI_Comm inner = MPI_COMM_NULL;
  SNEDE_PETSC(PetscCommDuplicate(comm, &inner, nullptr));
}

// PT-Scotch 7 splits a mesh differently from call to call, so would GAMG's and block Jacobi's
// iteration counts: its threads race, and its random generator goes on from the previous
// call. One thread (unless the user set SCOTCH_PTHREAD_NUMBER) and a reset generator make
// the same mesh split the same way every time.
void make_scotch_reproducible() {
  setenv("SCOTCH_PTHREAD_NUMBER", "1", /*overwrite=*/0);
#ifdef SNEDE_HAVE_PTSCOTCH
  SCOTCH_randomReset();
#endif
}

// Rank 0's verdict on its input, the same string on every rank ("" when it is fine).
std::string agreed_problem(MPI_Comm comm, const Mesh* serial) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string problem;
  if (rank == 0) {
    if (!serial) {
      problem = "distribute_mesh: rank 0 must pass the serial mesh";
    } else if (serial->n_live_points() != serial->n_points()) {
      problem = "distribute_mesh: the serial mesh has removed vertices; compact it first (Mesh.compacted)";
    } else {
      std::vector<char> used(static_cast<std::size_t>(serial->n_points()), 0);
      for (VertexId v : serial->cells()) used[static_cast<std::size_t>(v)] = 1;
      const auto unused = std::count(used.begin(), used.end(), 0);
      if (unused) problem = "distribute_mesh: " + std::to_string(unused) + " vertices of the serial mesh are in no cell";
    }
  }
  int length = static_cast<int>(problem.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, comm);
  problem.resize(static_cast<std::size_t>(length));
  MPI_Bcast(problem.data(), length, MPI_CHAR, 0, comm);
  return problem;
}

// The first rank's verdict on the parts (`what` names it), the same on every rank ("" when
// every part is fine).
std::string agreed_rank_cells(MPI_Comm comm, const RankCells& part) {
  std::int64_t dims[2] = {part.cell_dim, part.space_dim}, low[2] = {0, 0}, high[2] = {0, 0};
  MPI_Allreduce(dims, low, 2, MPI_INT64_T, MPI_MIN, comm);
  MPI_Allreduce(dims, high, 2, MPI_INT64_T, MPI_MAX, comm);
  std::int64_t vertices = 0;
  const bool whole_vertices = part.space_dim > 0 && part.coordinates.size() % static_cast<std::size_t>(part.space_dim) == 0;
  if (whole_vertices) vertices = static_cast<std::int64_t>(part.coordinates.size()) / part.space_dim;
  MPI_Allreduce(MPI_IN_PLACE, &vertices, 1, MPI_INT64_T, MPI_SUM, comm);
  std::string problem;
  const std::size_t corners = static_cast<std::size_t>(part.cell_dim) + 1;
  if (low[0] != high[0] || low[1] != high[1]) {
    problem = "the ranks give parts of different dimensions (cell_dim " + std::to_string(low[0]) + ".." +
              std::to_string(high[0]) + ", space_dim " + std::to_string(low[1]) + ".." + std::to_string(high[1]) + ")";
  } else if (part.cell_dim < 2 || part.cell_dim > 3 || part.space_dim < part.cell_dim || part.space_dim > 3) {
    problem = "cell_dim " + std::to_string(part.cell_dim) + " in space_dim " + std::to_string(part.space_dim) +
              ": triangles in 2D or 3D, or tetrahedra in 3D";
  } else if (!whole_vertices) {
    problem = "coordinates hold " + std::to_string(part.coordinates.size()) + " numbers, not " +
              std::to_string(part.space_dim) + " per vertex";
  } else if (part.cells.size() % corners) {
    problem = "cells hold " + std::to_string(part.cells.size()) + " ids, not " + std::to_string(corners) + " per cell";
  } else {
    for (std::int64_t v : part.cells)
      if (v < 0 || v >= vertices) {
        problem = "cell vertex id " + std::to_string(v) + " is outside 0.." + std::to_string(vertices - 1);
        break;
      }
  }
  return first_rank_problem(comm, "distribute_cells", problem);
}

// Distributes `dm` and takes this rank's part; `serial_id` gives the global vertex id of each of
// the DM's vertex points (indexed by point, −1 for the others), carried along the migration. The
// DMs are freed before snede's mesh is made, so that the two never hold the part at the same
// time.
DistributedMesh take_part(MPI_Comm comm, DmHandle dm, std::vector<PetscInt> serial_id, int cell_dim, int space_dim,
                          std::int64_t n_global_vertices, std::int64_t n_global_cells) {
  SfHandle migration;
  DmHandle distributed;
  // -petscpartitioner_type (and its options) choose how the cells are split.
  PetscPartitioner partitioner = nullptr;
  SNEDE_PETSC(DMPlexGetPartitioner(dm, &partitioner));
  SNEDE_PETSC(PetscPartitionerSetFromOptions(partitioner));
  make_scotch_reproducible();
  SNEDE_PETSC(DMPlexDistribute(dm, 0, migration.out(), distributed.out()));
  PetscInt chart_start = 0, chart_end = 0;
  std::vector<PetscInt> local_serial_id = serial_id;
  DM part = dm;
  if (distributed) {  // null on one rank: the DM is the part
    part = distributed;
    SNEDE_PETSC(DMPlexGetChart(part, &chart_start, &chart_end));
    local_serial_id.assign(static_cast<std::size_t>(chart_end - chart_start), -1);
    SNEDE_PETSC(PetscSFBcastBegin(migration, MPIU_INT, serial_id.data(), local_serial_id.data(), MPI_REPLACE));
    SNEDE_PETSC(PetscSFBcastEnd(migration, MPIU_INT, serial_id.data(), local_serial_id.data(), MPI_REPLACE));
    dm.reset();  // the whole (or the given parts) is no longer needed
    std::vector<PetscInt>().swap(serial_id);
  }
  SNEDE_PETSC(DMPlexGetChart(part, &chart_start, &chart_end));
  PetscInt c_start = 0, c_end = 0, v_start = 0, v_end = 0;
  SNEDE_PETSC(DMPlexGetHeightStratum(part, 0, &c_start, &c_end));
  SNEDE_PETSC(DMPlexGetDepthStratum(part, 0, &v_start, &v_end));
  // PETSc's vertex numbering (from the point SF): −(n + 1) marks a ghost whose owner numbers it n.
  IS numbering = nullptr;
  SNEDE_PETSC(DMPlexGetVertexNumbering(part, &numbering));
  const PetscInt* numbers = nullptr;
  SNEDE_PETSC(ISGetIndices(numbering, &numbers));
  std::vector<std::uint8_t> owned;
  std::vector<std::int64_t> global_number;
  for (PetscInt v = 0; v < v_end - v_start; ++v) {
    owned.push_back(numbers[v] >= 0);
    global_number.push_back(numbers[v] >= 0 ? numbers[v] : -(numbers[v] + 1));
  }
  SNEDE_PETSC(ISRestoreIndices(numbering, &numbers));

  Vec local_coordinates = nullptr;
  PetscSection section = nullptr;
  SNEDE_PETSC(DMGetCoordinatesLocal(part, &local_coordinates));
  SNEDE_PETSC(DMGetCoordinateSection(part, &section));
  const PetscScalar* x = nullptr;
  SNEDE_PETSC(VecGetArrayRead(local_coordinates, &x));
  std::vector<double> points;
  std::vector<std::int64_t> global_vertex;
  for (PetscInt v = v_start; v < v_end; ++v) {
    PetscInt offset = 0;
    SNEDE_PETSC(PetscSectionGetOffset(section, v, &offset));
    for (int d = 0; d < space_dim; ++d) points.push_back(PetscRealPart(x[offset + d]));
    global_vertex.push_back(local_serial_id[static_cast<std::size_t>(v - chart_start)]);
  }
  SNEDE_PETSC(VecRestoreArrayRead(local_coordinates, &x));

  std::vector<std::int64_t> local_cells;
  for (PetscInt c = c_start; c < c_end; ++c) {
    // The cell's vertices: its cone, or, in a mesh interpolated for a parallel partitioning,
    // the vertices of its closure.
    PetscInt* closure = nullptr;
    PetscInt size = 0;
    SNEDE_PETSC(DMPlexGetTransitiveClosure(part, c, PETSC_TRUE, &size, &closure));
    std::vector<std::int64_t> cell;
    for (PetscInt k = 0; k < size; ++k)
      if (closure[2 * k] >= v_start && closure[2 * k] < v_end) cell.push_back(closure[2 * k] - v_start);
    SNEDE_PETSC(DMPlexRestoreTransitiveClosure(part, c, PETSC_TRUE, &size, &closure));
    // DMPlex may reorient. A membrane's triangle (in 3D) has no signed area; its cone keeps the
    // serial corners' order, and its energy does not depend on the order.
    if (cell_dim == space_dim && simplex_orientation(points, space_dim, cell.data(), static_cast<int>(cell.size())) < 0) std::swap(cell[0], cell[1]);
    local_cells.insert(local_cells.end(), cell.begin(), cell.end());
  }

  distributed.reset();
  dm.reset();
  return DistributedMesh{.comm = comm,
                         .local = std::make_unique<Mesh>(cell_dim, space_dim, std::move(points), local_cells),
                         .global_vertex = std::move(global_vertex),
                         .owned = std::move(owned),
                         .global_number = std::move(global_number),
                         .n_global_vertices = n_global_vertices,
                         .n_global_cells = n_global_cells};
}

}  // namespace

DistributedMesh distribute_mesh(MPI_Comm comm, const Mesh* serial) {
  keep_petsc_communicator(comm);
  if (const std::string problem = agreed_problem(comm, serial); !problem.empty()) throw std::invalid_argument(problem);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  // Every rank learns the shape from rank 0.
  std::int64_t shape[4] = {0, 0, 0, 0};  // cell_dim, space_dim, vertices, cells
  if (rank == 0) shape[0] = serial->cell_dim(), shape[1] = serial->space_dim(), shape[2] = serial->n_points(),
                 shape[3] = static_cast<std::int64_t>(serial->n_cells());
  MPI_Bcast(shape, 4, MPI_INT64_T, 0, comm);
  const int cell_dim = static_cast<int>(shape[0]), space_dim = static_cast<int>(shape[1]);
  const PetscInt corners = cell_dim + 1;

  std::vector<PetscInt> cells;
  std::vector<PetscReal> coordinates;
  PetscInt n_cells = 0, n_vertices = 0;
  if (rank == 0) {
    for (VertexId v : serial->cells()) cells.push_back(static_cast<PetscInt>(v));
    coordinates.assign(serial->points().begin(), serial->points().end());
    n_cells = static_cast<PetscInt>(shape[3]);
    n_vertices = static_cast<PetscInt>(shape[2]);
  }
  DmHandle dm;
  SNEDE_PETSC(DMPlexCreateFromCellListPetsc(comm, cell_dim, n_cells, n_vertices, corners, PETSC_FALSE, cells.data(),
                                            space_dim, coordinates.data(), dm.out()));
  // The serial id of every vertex point travels with the distribution (the migration SF).
  PetscInt chart_start = 0, chart_end = 0;
  SNEDE_PETSC(DMPlexGetChart(dm, &chart_start, &chart_end));
  std::vector<PetscInt> serial_id(static_cast<std::size_t>(chart_end - chart_start), -1);
  for (PetscInt v = 0; v < n_vertices; ++v) serial_id[static_cast<std::size_t>(n_cells + v)] = v;
  return take_part(comm, std::move(dm), std::move(serial_id), cell_dim, space_dim, shape[2], shape[3]);
}

DistributedMesh distribute_cells(MPI_Comm comm, RankCells given, bool keep_as_given) {
  keep_petsc_communicator(comm);
  const std::string problem = agreed_rank_cells(comm, given);
  if (!problem.empty()) throw std::invalid_argument(problem);
  const PetscInt corners = given.cell_dim + 1;
  const auto n_cells = static_cast<PetscInt>(given.cells.size() / static_cast<std::size_t>(corners));
  const auto n_owned = static_cast<PetscInt>(given.coordinates.size() / static_cast<std::size_t>(given.space_dim));
  std::int64_t totals[2] = {static_cast<std::int64_t>(n_owned), static_cast<std::int64_t>(n_cells)};
  MPI_Allreduce(MPI_IN_PLACE, totals, 2, MPI_INT64_T, MPI_SUM, comm);
  // Parts as given are kept when they are balanced (the largest at most 1.2 times the mean, as
  // a generator's are) and made without DMPlex (part_as_given.hpp); else DMPlex partitions them
  // anew, which in parallel needs the faces and edges (an interpolated mesh: more memory while
  // it lasts).
  std::int64_t largest = static_cast<std::int64_t>(n_cells);
  MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_INT64_T, MPI_MAX, comm);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  if (keep_as_given || static_cast<double>(largest) * ranks <= 1.2 * static_cast<double>(totals[1]))
    return part_as_given(comm, std::move(given), totals[0], totals[1]);

  std::vector<PetscInt> cells(given.cells.begin(), given.cells.end());
  DmHandle dm;
  // The global ids of the vertices of this rank's cells, in the DM's vertex point order (sorted).
  // PETSc 3.18 writes them into an array the caller gives (later versions allocate it).
  std::vector<PetscInt> adjacent_ids(cells);
  std::sort(adjacent_ids.begin(), adjacent_ids.end());
  adjacent_ids.erase(std::unique(adjacent_ids.begin(), adjacent_ids.end()), adjacent_ids.end());
  PetscInt* adjacent = adjacent_ids.data();
  SNEDE_PETSC(DMPlexCreateFromCellListParallelPetsc(comm, given.cell_dim, n_cells, n_owned,
                                                    static_cast<PetscInt>(totals[0]), corners, PETSC_FALSE,
                                                    cells.data(), given.space_dim, given.coordinates.data(), nullptr,
                                                    &adjacent, dm.out()));
  std::vector<PetscInt>().swap(cells);
  {
    DmHandle interpolated;
    SNEDE_PETSC(DMPlexInterpolate(dm, interpolated.out()));
    dm = std::move(interpolated);
  }
  DM mesh = dm;
  PetscInt chart_start = 0, chart_end = 0, v_start = 0, v_end = 0;
  SNEDE_PETSC(DMPlexGetChart(mesh, &chart_start, &chart_end));
  SNEDE_PETSC(DMPlexGetDepthStratum(mesh, 0, &v_start, &v_end));
  std::vector<PetscInt> serial_id(static_cast<std::size_t>(chart_end - chart_start), -1);
  if (static_cast<std::size_t>(v_end - v_start) != adjacent_ids.size())
    throw std::logic_error("distribute_cells: DMPlex made " + std::to_string(v_end - v_start) + " vertices of " +
                           std::to_string(adjacent_ids.size()) + " ids");
  for (PetscInt v = v_start; v < v_end; ++v) serial_id[static_cast<std::size_t>(v - chart_start)] = adjacent[v - v_start];
  std::vector<PetscInt>().swap(adjacent_ids);
  DistributedMesh result = take_part(comm, std::move(dm), std::move(serial_id), given.cell_dim, given.space_dim, totals[0],
                                     totals[1]);
  std::int64_t owned = std::count(result.owned.begin(), result.owned.end(), std::uint8_t{1});
  MPI_Allreduce(MPI_IN_PLACE, &owned, 1, MPI_INT64_T, MPI_SUM, comm);
  if (owned != totals[0])
    throw std::invalid_argument("distribute_cells: " + std::to_string(totals[0] - owned) + " of the " +
                                std::to_string(totals[0]) + " vertices are in no cell");
  return result;
}

}  // namespace snede
