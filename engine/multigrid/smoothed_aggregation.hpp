// Smoothed aggregation (Vaněk, Mandel and Brezina): each aggregation level's interpolation
// smoothed by one damped Jacobi step, serially and on MPI ranks alike (the matrices are
// sequential or MPIAIJ; every call is collective on their communicator).
//
// The first level: P₁ = Π (I − ω D⁻¹ L) T₁ with L = L_graph ⊗ I the mesh's graph Laplacian (an
// edge weighs the number of cells that share it), ω = 2/3 (λ_max(D⁻¹L) ≤ 2) and Π the
// constraints' projection. The coarse functions then overlap and decay across aggregate borders
// instead of jumping, which is what makes the coarse correction good; L is the mesh's own (no
// edge across a cut), so they never reach across the lips, and it does not depend on the state,
// so the levels are made once per mesh and kept through Newton iterations. On ranks each rank adds
// its own cells' edges into a distributed matrix, so an edge between two ranks' cells weighs what
// it weighs serially, and the smoothed functions reach into the neighbouring ranks' aggregates.
//
// The later levels (issue 52, item 4): P_{l+1} = (I − ω_l D_l⁻¹ A_l) T_{l+1} with A_l = P_lᵀ A_{l−1} P_l
// the Galerkin product of L through the levels already smoothed (A₀ = L), D_l its diagonal and
// ω_l = 4 / (3 λ_max(D_l⁻¹ A_l)), λ_max by power iteration. With plain aggregates below the first
// level the rank mg took 25 CG iterations on the 10⁶-tetrahedron cube against the serial grid
// levels' 16 (piecewise rigid coarse functions: a deep hierarchy's corrections jump at the
// aggregates' borders); smoothed, 16.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <span>
#include <vector>

#include "core/petsc_handle.hpp"
#include "mesh/mesh.hpp"
#include "multigrid/node_aggregation.hpp"

namespace snede {

// The vertex graph of `mesh`'s cells as a matrix on `comm` (rows this process's `n_rows`): entry
// (row_of_vertex[a], row_of_vertex[b]) the number of this process's cells with the edge ab, summed
// over the processes (a row another rank owns gets its contributions).
MatHandle cell_edge_adjacency(MPI_Comm comm, const Mesh& mesh, std::span<const std::int64_t> row_of_vertex,
                              PetscInt n_rows);

// Smooths the levels' interpolations (the tentative ones, finest first, each from a level to the
// next finer one) in place: the first, whose rows are `dim` dofs per row of `adjacency`, as above with
// Π's block of row r's vertex given by projection(vertex_of_row[r − first row]); the later ones
// too when `coarse_levels_too`.
void smooth_interpolations(Mat adjacency, int dim, std::span<const VertexId> vertex_of_row,
                           const VertexProjection& projection, std::span<AggregateLevel> finest_first,
                           bool coarse_levels_too);

}  // namespace snede
