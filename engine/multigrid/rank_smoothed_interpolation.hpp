// The first aggregation level's interpolation smoothed on MPI ranks, as serially
// (aggregation_multigrid.cpp, smoothed_interpolation): P = Π (I − ω D⁻¹ L) T with L the whole
// mesh's graph Laplacian (an edge weighs the number of cells that share it), ω = 2/3 and Π the
// constraints' projection. Each rank adds its own cells' edges into a distributed adjacency
// matrix, so an edge between two ranks' cells weighs what it weighs serially (PETSc sums the
// contributions to rows another rank owns); the owners then read their rows whole. The
// smoothed coarse functions overlap the neighbouring ranks' aggregates: P gains off-rank
// entries, which PETSc's MatMatMult and the Galerkin products handle.
#pragma once

#include "core/petsc_handle.hpp"
#include "mesh/distributed_mesh.hpp"
#include "multigrid/node_aggregation.hpp"

namespace snede {

// Collective. `tentative`: the first level's interpolation, rows the problem's (owned vertices'
// dofs at global_number·dim + k); `projection` gives Π's block of each local vertex.
MatHandle rank_smoothed_interpolation(const DistributedMesh& part, const VertexProjection& projection, Mat tentative);

}  // namespace snede
