// The tangent J = s·(P K(u) P + c (I − P)) of model.hpp, with entries: assembled from the element
// stiffness matrices (the same kernels as the shell, ElasticBody::element_stiffness), or only
// its diagonal. For preconditioners that need entries (Jacobi, GAMG, ILU, ...) and for
// comparison; the shell stays the operator of every solve, because a cut or a bisection
// invalidates an assembled matrix (its sparsity is rebuilt for the new mesh).
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

#include "core/csr_matrix.hpp"
#include "core/petsc_handle.hpp"
#include "solve/model.hpp"
#include "solve/problem.hpp"

namespace snede {

// What a membrane element contributes: its exact tangent, or its positive part (eigenvalues
// raised to a small positive floor) for a preconditioner, which must stay positive semidefinite where
// the sheet is compressed and its tangent indefinite (tangent_assembly.cpp). Volume elements
// always contribute their exact tangent.
enum class MembraneTangent { exact, positive_part };

// J with the block sparsity of the mesh it was made for: a dim × dim block for every pair of
// vertices that share an element (under a smoothed formulation: that are at most two edges
// apart), and a diagonal block for every vertex (removed ones too).
class AssembledTangent {
 public:
  AssembledTangent(const Model& model, MatrixFormat format, MembraneTangent membranes = MembraneTangent::exact);
  // Whether the mesh is still the one this matrix was made for (no edit since).
  bool matches(const Model& model) const;
  // Takes over the mesh as it is now if only vertices moved since (a cut's snap): true, and the
  // sparsity is kept (assemble() fills the values for the new shapes); false if elements or
  // vertices were added or removed.
  bool follow_moved_vertices(const Model& model);
  // Fills the matrix with J at u, scaled by the model's operator scale s as the shell is.
  // Values are added straight into PETSc's value array at offsets found once per mesh (AIJ or
  // BAIJ alike).
  void assemble(const Model& model, Vec u);
  Mat mat() const { return A_; }

 private:
  MembraneTangent membranes_;
  std::uint64_t revision_;
  std::uint64_t topology_revision_;
  MatHandle A_;
  std::vector<std::int32_t> block_rank_;  // per element id and block (a, b): b's place among
                                          // a's sorted neighbours
  std::vector<std::int32_t> self_rank_;   // per vertex: its own place among its neighbours
  bool patches_ = false;                  // a smoothed formulation's patches: blocks to two edges
  std::vector<std::size_t> neighbour_start_;  // patches only: each vertex's sorted neighbours (CSR)
  std::vector<VertexId> neighbours_;
  // J's entries at u, scaled, added into A_'s arrays (zeroed first).
  void add_entries(const Model& model, Vec u, const CsrView& A) const;
  // Each block's place among its row's neighbours, for a patch's sorted vertices (count²).
  const std::int32_t* patch_block_ranks(std::span<const VertexId> vertices, std::vector<std::int32_t>& ranks) const;
};

// The rigid-body motions of the reference configuration as A's near null space (what GAMG
// needs to coarsen elasticity well).
void set_rigid_body_near_null_space(const Model& model, Mat A);

// The diagonal of J at u (scaled like the shell), without forming J.
void tangent_diagonal(const Model& model, Vec u, Vec diagonal);

}  // namespace snede
