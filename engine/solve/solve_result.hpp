// What every solve returns: converged or not and PETSc's reason, never a crash.
#pragma once

#include <string>
#include <vector>

namespace snede {

struct SolveResult {
  bool converged = false;
  std::string reason;          // PETSc's reason name (SNES_/KSP_/TS_ prefix dropped), or snede's own
  int iterations = 0;          // nonlinear iterations, KSP iterations for linear CG, steps for dynamics
  int linear_iterations = 0;   // inner KSP iterations (Newton), 0 otherwise
  double residual_norm = 0;    // ‖F(u)‖ at the end
  double initial_residual_norm = 0;
  double tolerance = 0;        // the stopping threshold used
  double energy = 0;           // Π(u) at the end
  double seconds = 0;          // wall time of the solve
  double flops = 0;            // PETSc-logged flops of the solve
  std::vector<double> residual_history;
};

}  // namespace snede
