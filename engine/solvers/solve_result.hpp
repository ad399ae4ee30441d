// What every solve returns: converged or not and PETSc's reason, never a crash.
#pragma once

#include <string>
#include <vector>

namespace snede {

struct SolveResult {
  bool converged = false;
  std::string reason;          // PETSc's reason name (SNES_/KSP_/TS_ prefix dropped), or snede's own
  int iterations = 0;          // nonlinear iterations, KSP iterations for linear CG, steps for dynamics
  double residual_norm = 0;    // ‖F(u)‖ at the end
  double energy = 0;           // Π(u) at the end
  double seconds = 0;          // wall time of the solve
  double flops = 0;            // PETSc-logged flops of the solve
  int linear_iterations = 0;   // inner KSP iterations (Newton), 0 otherwise
  double initial_residual_norm = 0;
  double tolerance = 0;        // the stopping threshold used
  std::vector<double> residual_history;

  // Every field with its name, in this order: the one list that bindings and printing read.
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("converged", &SolveResult::converged);
    visit("reason", &SolveResult::reason);
    visit("iterations", &SolveResult::iterations);
    visit("residual_norm", &SolveResult::residual_norm);
    visit("energy", &SolveResult::energy);
    visit("seconds", &SolveResult::seconds);
    visit("flops", &SolveResult::flops);
    visit("linear_iterations", &SolveResult::linear_iterations);
    visit("initial_residual_norm", &SolveResult::initial_residual_norm);
    visit("tolerance", &SolveResult::tolerance);
    visit("residual_history", &SolveResult::residual_history);
  }
};

// One line for people: "converged (REASON) after 3 iterations (41 linear): |r| = …
// (tolerance …), energy … J, 0.012 s, 5.1 MFLOP".
std::string summary(const SolveResult& result);

// Converged means the stopping criterion holds at an admissible, finite final state, whatever
// stopped PETSc (a line search's step tolerance, say): result.residual_norm and
// result.tolerance are those of the final state; `inadmissible` names why it is not admissible
// (empty if it is); `finite` and `inverted` are the final residual's check (problem.hpp).
void judge_final_state(SolveResult& result, const std::string& inadmissible, bool finite, bool inverted);

}  // namespace snede
