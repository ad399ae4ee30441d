#include "mesh/distributed_mesh.hpp"

#include <petscdmplex.h>
#include <petscsf.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"

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

// The signed volume (area) of a volume mesh's simplex, to restore snede's positive orientation.
double orientation(const std::vector<double>& points, int space_dim, const std::vector<std::int64_t>& cell) {
  const auto at = [&](std::size_t k, int d) { return points[static_cast<std::size_t>(cell[k]) * space_dim + d]; };
  if (cell.size() == 3) {
    return (at(1, 0) - at(0, 0)) * (at(2, 1) - at(0, 1)) - (at(1, 1) - at(0, 1)) * (at(2, 0) - at(0, 0));
  }
  double e[3][3];
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) e[k][d] = at(k + 1, d) - at(0, d);
  return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
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

  // -petscpartitioner_type (and its options) choose how the cells are split.
  PetscPartitioner partitioner = nullptr;
  SNEDE_PETSC(DMPlexGetPartitioner(dm, &partitioner));
  SNEDE_PETSC(PetscPartitionerSetFromOptions(partitioner));
  make_scotch_reproducible();
  SfHandle migration;
  DmHandle distributed;
  SNEDE_PETSC(DMPlexDistribute(dm, 0, migration.out(), distributed.out()));
  std::vector<PetscInt> local_serial_id = serial_id;
  DM part = dm;
  if (distributed) {
    part = distributed;
    SNEDE_PETSC(DMPlexGetChart(part, &chart_start, &chart_end));
    local_serial_id.assign(static_cast<std::size_t>(chart_end - chart_start), -1);
    SNEDE_PETSC(PetscSFBcastBegin(migration, MPIU_INT, serial_id.data(), local_serial_id.data(), MPI_REPLACE));
    SNEDE_PETSC(PetscSFBcastEnd(migration, MPIU_INT, serial_id.data(), local_serial_id.data(), MPI_REPLACE));
  }

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
    const PetscInt* cone = nullptr;
    PetscInt size = 0;
    SNEDE_PETSC(DMPlexGetConeSize(part, c, &size));
    SNEDE_PETSC(DMPlexGetCone(part, c, &cone));
    std::vector<std::int64_t> cell(cone, cone + size);
    for (auto& v : cell) v -= v_start;
    // DMPlex may reorient. A membrane's triangle (in 3D) has no signed area; its cone keeps the
    // serial corners' order, and its energy does not depend on the order.
    if (cell_dim == space_dim && orientation(points, space_dim, cell) < 0) std::swap(cell[0], cell[1]);
    local_cells.insert(local_cells.end(), cell.begin(), cell.end());
  }

  DistributedMesh result;
  result.comm = comm;
  result.local = std::make_unique<Mesh>(cell_dim, space_dim, std::move(points), local_cells);
  result.global_vertex = std::move(global_vertex);
  result.owned = std::move(owned);
  result.global_number = std::move(global_number);
  result.n_global_vertices = shape[2];
  result.n_global_cells = shape[3];
  return result;
}

}  // namespace snede
