// The unit square or cube as the distributed tests' mesh: made whole (on every rank, it is
// small) and distributed over MPI_COMM_WORLD by DMPlex from rank 0.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <vector>

#include "mesh/distributed_mesh.hpp"
#include "mesh/fixtures.hpp"

namespace snede::testing {

inline int world_rank() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

// The unit square (n × n squares, two triangles each) or cube (n³ Kuhn-split cubes); vertex
// (i, j[, k]) has id (i (n + 1) + j) (n + 1) + k.
inline Mesh unit_box(int dim, int n) {
  const std::vector<std::vector<VertexId>> cells = dim == 2 ? grid_triangles(n, n) : kuhn_box(n);
  std::vector<double> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      if (dim == 2) {
        points.insert(points.end(), {double(i) / n, double(j) / n});
        continue;
      }
      for (int k = 0; k <= n; ++k) points.insert(points.end(), {double(i) / n, double(j) / n, double(k) / n});
    }
  std::vector<std::int64_t> flat;
  for (const auto& cell : cells) flat.insert(flat.end(), cell.begin(), cell.end());
  return Mesh(dim, dim, std::move(points), flat);
}

// Collective: the box distributed over MPI_COMM_WORLD.
inline DistributedMesh distributed_box(int dim, int n) {
  const Mesh serial = unit_box(dim, n);
  return distribute_mesh(MPI_COMM_WORLD, world_rank() == 0 ? &serial : nullptr);
}

}  // namespace snede::testing
