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
#include "mesh/edit_footprint.hpp"
#include "problem/model.hpp"
#include "problem/problem.hpp"

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
  // The tangent of the mesh as it is now, made from `earlier` (filled, for the mesh before the
  // edits `edits` recorded since it was made): the rows of vertices no edit touched keep their
  // columns, the others' come from the elements around them; its values are earlier's where no
  // edit reached, and J's at u in every block whose row or column vertex an edit touched or whose
  // constraints changed (the few hundred blocks around a cut, instead of every element's matrix
  // and the whole mesh's vertex stars again). Where
  // the state moved since earlier was filled, the kept blocks are of that state: a preconditioner's
  // matrix, lagged as kept levels are. With u null, the sparsity alone (values zero, for
  // assemble()). Check can_follow_edits (and, with u, values_can_follow_edits) first.
  AssembledTangent(const Model& model, const AssembledTangent& earlier, const EditFootprint& edits, Vec u);
  // Whether this tangent's sparsity can make the next one's that way: P1 (a smoothed
  // formulation's patches reach two edges: not done) and no vertex removed from the id range.
  bool can_follow_edits(const Model& model) const;
  // ... and its values too: filled, for the model's operator scale.
  bool values_can_follow_edits(const Model& model) const;
  // Whether the values are J's at some state (assembled, or made from a filled earlier one).
  bool filled() const { return filled_; }
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
  MatrixFormat format_;
  std::uint64_t revision_;
  std::uint64_t topology_revision_;
  MatHandle A_;
  std::vector<std::int32_t> block_rank_;  // per element id and block (a, b): b's place among
                                          // a's sorted neighbours
  std::vector<std::int32_t> self_rank_;   // per vertex: its own place among its neighbours
  bool patches_ = false;                  // a smoothed formulation's patches: blocks to two edges
  std::vector<std::size_t> neighbour_start_;  // each vertex's sorted neighbours, itself included (CSR)
  std::vector<VertexId> neighbours_;
  // The sparsity from the whole mesh's vertex stars: neighbours, block and self ranks.
  void find_neighbours(const Model& model);
  // The same after edits, from `earlier`'s: the rows of the vertices `touched` (by the edits, or
  // added since) from the elements around them, the others' copied, and the ranks of the
  // elements with a touched corner found anew (the rest copied: the same elements, the same ids).
  void follow_neighbours(const Model& model, const AssembledTangent& earlier, const std::vector<bool>& touched);
  // A_ with the sparsity of the neighbours, zero values.
  void make_matrix(int d);
  // What the last assemble() filled the values with: the operator scale, the constrained
  // directions' stiffness c and every vertex's block of P (follow_edits compares them).
  bool filled_ = false;
  double filled_scale_ = 0;
  double filled_constraint_stiffness_ = 0;
  std::vector<double> filled_projections_;
  void record_fill(const Model& model, std::vector<double> projections);
  // J's entries at u, scaled, added into A_'s arrays (P: every vertex's block): every element's;
  // or, given `fresh` (per vertex) and `only`, those of the elements `only` in the blocks with a
  // fresh row or column vertex, and c (I − P) on the fresh rows.
  void add_entries(const Model& model, Vec u, const CsrView& A, const std::vector<double>& P,
                   const std::vector<bool>* fresh = nullptr, const std::vector<ElementId>* only = nullptr) const;
  // The edit of the constructor above: earlier's values copied for the vertices neither `fresh`
  // (touched by the edits or added) nor with changed constraints, J's added on the others.
  void take_values(const Model& model, const AssembledTangent& earlier, std::vector<bool> fresh, Vec u);
  // Each block's place among its row's neighbours, for a patch's sorted vertices (count²).
  const std::int32_t* patch_block_ranks(std::span<const VertexId> vertices, std::vector<std::int32_t>& ranks) const;
};

// The rigid-body motions of the reference configuration as A's near null space (what GAMG
// needs to coarsen elasticity well).
void set_rigid_body_near_null_space(const Model& model, Mat A);

// The diagonal of J at u (scaled like the shell), without forming J.
void tangent_diagonal(const Model& model, Vec u, Vec diagonal);

}  // namespace snede
