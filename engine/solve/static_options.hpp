// A static solver's settings (static_solver.hpp): the method, the stopping rule (§6.6), the
// iteration cap, the options prefix, the preconditioner and the solver's own PETSc options.
#pragma once

#include <string>

#include "core/solver_options.hpp"
#include "solve/stopping.hpp"

namespace snede {

enum class StaticMethod { linear_cg, nonlinear_cg, newton };

struct StaticOptions {
  StaticMethod method = StaticMethod::newton;
  StoppingRule stopping;  // force_scale and n_dofs are filled from the model
  int max_iterations = 10000;
  std::string options_prefix = "static_";
  // The PETSc PC type of the CG (linear, or Newton's inner one): "none", "jacobi" (from the
  // shell's diagonal, no matrix), "gamg" (on an assembled tangent with the rigid-body near null
  // space), "mg" (multigrid for any volume mesh: on the bisection hierarchy, matrix-free on
  // every level, when the mesh has one whose coarser levels are conforming; else on a
  // background grid with virtual nodes or by aggregation, Galerkin levels from an assembled
  // tangent; -<prefix>mg_coarsening auto|bisection|grid|aggregation chooses) or any PETSc PC
  // that works on an assembled matrix ("ilu", "icc", ...).
  // "auto": "mg" for cg and newton on volume meshes of 1 000 cells or more, else "none".
  // Empty: -<prefix>pc_type if given, else "auto". -<prefix>pc_type on the command line wins.
  std::string preconditioner;
  OptionList petsc_options;  // this solver's PETSc options, without the prefix
};

}  // namespace snede
