// How snede's truncated Newton (§2.4.3) steps, beyond PETSc's SNESNEWTONLS: the inner CG's
// forcing, the search direction checked and projected before the line search, and full steps
// when the energy line search stalls at the round-off of Π near the solution.
#pragma once

#include <petscsnes.h>

#include <functional>
#include <string>

#include "core/solver_options.hpp"

#include "multigrid/multigrid.hpp"
#include "problem/problem.hpp"

namespace snede {

// Newton with a line search (snede's default), not a trust region (-snes_type newtontr), which
// has no line search to finish with and rejects steps without a stall.
bool is_line_search_newton(SNES snes);

// The inner CG's relative tolerance, unless the options under `prefix` choose one
// (snes_ksp_ew, ksp_rtol): Eisenstat–Walker's forcing without a PC, else a fixed tolerance,
// looser when Galerkin levels are kept through the solve (`levels_kept`).
void choose_forcing(SNES snes, const SolverOptions& options, const std::string& prefix, bool preconditioned,
                    bool levels_kept);

// The search direction from the inner CG's step, as a line-search pre-check: projected onto
// the allowed motions (6.7), and where CG gave no descent direction the preconditioned steepest
// descent, scaled by its curvature. `levels`: the multigrid levels of the PC (may be null),
// told to make themselves positive definite when CG found the PC indefinite.
void make_descent_direction(SNESLineSearch line_search, Vec step, Problem& problem, Multigrid* levels);

// After the line search stopped Newton (DIVERGED_LINE_SEARCH or DIVERGED_LOCAL_MIN) with
// `iterations` of `max_iterations` taken: a few full steps by `run` (which solves again and sets
// `reason`), kept only if they converge; otherwise the state u and `reason` are put back.
void finish_with_full_steps(SNES snes, Vec u, PetscInt max_iterations, PetscInt iterations,
                            SNESConvergedReason& reason, const std::function<void()>& run);

}  // namespace snede
