// A static solver's settings (static_solver.hpp): the method, the stopping rule (§6.6), the
// iteration cap, the options prefix, the preconditioner and the solver's own PETSc options.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>

#include "core/enum_names.hpp"
#include "core/solver_options.hpp"
#include "problem/stopping.hpp"

namespace snede {

enum class StaticMethod { linear_cg, nonlinear_cg, newton };

// Every method with the name users give it (method=): the one list both directions read.
inline constexpr std::array static_method_names{
    named(StaticMethod::linear_cg, "cg"),
    named(StaticMethod::nonlinear_cg, "ncg"),
    named(StaticMethod::newton, "newton"),
};
// The bindings find a field's names here: Python reads and writes the method by name.
constexpr const auto& enum_names(StaticMethod) { return static_method_names; }

// A name of static_method_names; anything else is a std::invalid_argument naming the value.
inline StaticMethod static_method(const std::string& name) { return enum_value(static_method_names, "method", name); }
inline std::string static_method_name(StaticMethod method) { return enum_name(static_method_names, method); }

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
  // "auto": "mg" for cg and newton from multigrid_from_cells cells on, else "none".
  // Empty: -<prefix>pc_type if given, else "auto". -<prefix>pc_type on the command line wins.
  std::string preconditioner;
  // Where "auto" starts multigrid. A solve from rest: on the cantilever block
  // (studies/benchmarks/static_solve_scaling.py, docs/results/interactive.md) mg and no
  // preconditioner cost the same at about 650 cells, mg is 1.3× faster at 1 500, 2–3× at
  // 5 000–40 000; membranes 1.3–5× faster from 1 000 triangles on sheets and organ skins (a slack
  // sheet loaded across its plane excepted), mixed below. A loop of small corrections whose
  // system changes at most solves sets its own (needle_insertion.cpp).
  std::int64_t multigrid_from_cells = 1000;
  OptionList petsc_options;  // this solver's PETSc options, without the prefix

  // Every setting with its name (the stopping rule's by theirs; force_scale and n_dofs are the
  // model's, not settings): the one list that bindings read.
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("method", &StaticOptions::method);
    visit("rtol", [](auto& options) -> auto& { return options.stopping.rtol; });
    visit("criterion", [](auto& options) -> auto& { return options.stopping.criterion; });
    visit("round_tolerance", [](auto& options) -> auto& { return options.stopping.round_tolerance; });
    visit("max_iterations", &StaticOptions::max_iterations);
    visit("options_prefix", &StaticOptions::options_prefix);
    visit("petsc_options", &StaticOptions::petsc_options);
    visit("preconditioner", &StaticOptions::preconditioner);
  }
};

// The settings of DistributedStatic.solve unless told otherwise (issue 18's route): linear CG
// without a preconditioner to ε‖r(u₀)‖ with ε = 1e-8, options prefix "dstatic_". Issue 52
// makes one problem of the serial and distributed routes and, with it, one set of defaults.
StaticOptions distributed_solve_options();

// std::invalid_argument naming the first setting out of range (rtol, round_tolerance,
// max_iterations, linear CG on a material that is not linear), or the setting that differs
// between the ranks of `comm`: a rank with another method or tolerance would wait in a
// collective call the others never make. Collective.
void require_valid(const StaticOptions& options, bool linear_material, MPI_Comm comm);

}  // namespace snede
