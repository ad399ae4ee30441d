// The tangent of a distributed static problem assembled into a PETSc MPIAIJ matrix, for the
// preconditioners that need entries (GAMG, issue 18). Each rank adds the element stiffnesses
// of its own cells, projected on both sides by the constraints (P_a K_ab P_b, the kernels of
// ElasticBody as the serial AssembledTangent takes them: projected_stiffness.hpp) at the global
// rows of their vertices; the ghosts' rows go to their owners at assembly. The owners add each
// of their vertices' block of c (I − P): J = P K P + c (I − P), as the shell applies it (c the
// constrained directions' stiffness, projected_stiffness.hpp).
// A membrane element contributes its positive part, as serially for a preconditioner.
//
// As the serial AssembledTangent does, the sparsity is found once from the cells' vertex stars
// and each element block's place in PETSc's own arrays once; an assembly then adds the element
// blocks of owned rows straight into the arrays and sends only the ghost rows. (Inserting every
// element's 144 entries through MatSetValues, after a MATPREALLOCATOR pass of the same, cost
// 1.8 + 2.3 s per rank at 10⁶ tetrahedra on 2 ranks, ten times the serial assembly per cell.)
// Each owner's rows are the union of its cells' stars and of the ghost rows other ranks send it
// once, so every later assembly's contributions land in preallocated entries. The rigid-body
// motions of the reference configuration are the near null space GAMG coarsens with.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/petsc_handle.hpp"
#include "fem/elastic_body.hpp"
#include "mesh/distributed_mesh.hpp"

namespace snede {

class DistributedAssembledTangent {
 public:
  // Collective. local_rows: the global row of each local dof (owned and ghost; vertex v's dofs
  // are rows dim·global_number[v] + i); projection: P's dim × dim block (row-major) of each
  // local vertex, one after another (projection_blocks); n_owned_dofs: the rows this rank
  // owns; constraint_stiffness: c (the same on every rank).
  DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body, std::span<const PetscInt> local_rows,
                              std::span<const double> projection, PetscInt n_owned_dofs,
                              double constraint_stiffness = 1.0);
  // The same with whole dofs fixed: fixed_local is 1 for a fixed local dof (P's blocks are
  // diagonal, 0 there and 1 elsewhere).
  DistributedAssembledTangent(const DistributedMesh& part, const ElasticBody& body, std::span<const PetscInt> local_rows,
                              std::span<const std::uint8_t> fixed_local, PetscInt n_owned_dofs,
                              double constraint_stiffness = 1.0);
  // Collective: J at the local displacement u (owned and ghost dofs).
  void assemble(std::span<const double> u);
  Mat mat() const { return A_; }

 private:
  // Each local vertex's neighbours (itself included) sorted by global number, and each element
  // block's place among its row's neighbours.
  void find_neighbours();
  // Preallocates and fixes the structure: owned rows' columns from this rank's stars and the
  // ghost rows the other ranks send (collective).
  void make_matrix(PetscInt n_owned_dofs);
  // Where each (vertex, neighbour) block is added: slot_ (see below).
  void find_slots();
  // Sends the ghost rows' values to their owners (through MatSetValues' stash).
  void add_ghost_rows();

  const DistributedMesh& part_;
  const ElasticBody& body_;
  int dim_, corners_;
  std::vector<PetscInt> local_rows_;
  std::vector<double> projection_, complement_;  // per local vertex, dim × dim blocks: P, c (I − P)
  PetscInt first_block_ = 0;                     // this rank's first owned vertex's global number
  std::vector<std::size_t> neighbour_start_;     // per local vertex, into neighbours_ (+ 1 at the end)
  std::vector<VertexId> neighbours_;             // per local vertex, by global number
  std::vector<std::int32_t> block_rank_;         // per element id × corners × corners
  std::vector<std::int32_t> self_rank_;          // per local vertex: its own place among its neighbours
  // Per neighbours_ entry: an owned row's block is at this column offset in PETSc's diagonal
  // part (≥ 0) or at −1 − slot in the off-diagonal part; a ghost row's block is the slot-th
  // dim × dim block of ghost_values_.
  std::vector<std::int32_t> slot_;
  std::vector<double> ghost_values_;
  MatHandle A_;
};

}  // namespace snede
