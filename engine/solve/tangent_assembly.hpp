// The tangent J = s·(P K(u) P + (I − P)) of model.hpp, with entries: assembled from the element
// stiffness matrices (the same kernels as the shell, ElasticBody::element_stiffness), or only
// its diagonal. For preconditioners that need entries (Jacobi, GAMG, ILU, ...) and for
// comparison; the shell stays the operator of every solve, because a cut or a bisection
// invalidates an assembled matrix (its sparsity is rebuilt for the new mesh).
#pragma once

#include <petscmat.h>

#include "core/petsc_handle.hpp"
#include "solve/model.hpp"

namespace snede {

enum class MatrixFormat { aij, baij };

// A matrix with the block sparsity of the current mesh: a dim × dim block for every pair of
// vertices that share an element, and a diagonal block for every vertex (removed ones too).
MatHandle create_tangent_matrix(const Model& model, MatrixFormat format);

// Fills A (from create_tangent_matrix, for the current mesh) with J at u, scaled by the
// model's operator scale s as the shell is.
void assemble_tangent(const Model& model, Vec u, Mat A);

// The rigid-body motions of the reference configuration as A's near null space (what GAMG
// needs to coarsen elasticity well).
void set_rigid_body_near_null_space(const Model& model, Mat A);

// The diagonal of J at u (scaled like the shell), without forming J.
void tangent_diagonal(const Model& model, Vec u, Vec diagonal);

}  // namespace snede
