#include "solvers/solve_result.hpp"

#include <cmath>

#include "core/formatted.hpp"

namespace snede {

std::string summary(const SolveResult& r) {
  std::string line = (r.converged ? "converged (" : "NOT converged (") + r.reason + ") after " +
                     std::to_string(r.iterations) + " iterations";
  if (r.linear_iterations) line += " (" + std::to_string(r.linear_iterations) + " linear)";
  return line + formatted(": |r| = %.3e (tolerance %.3e), energy %.6e J, %.3f s, %.1f MFLOP", r.residual_norm,
                          r.tolerance, r.energy, r.seconds, r.flops / 1e6);
}

void judge_final_state(SolveResult& result, const std::string& inadmissible, bool finite, bool inverted) {
  if (!inadmissible.empty()) {
    result.converged = false;
    result.reason = inadmissible;
  }
  // (A distributed problem's residual is NaN at an inverted state, already named above.)
  if (!finite || (!inverted && !std::isfinite(result.residual_norm))) {
    result.converged = false;
    result.reason = "DIVERGED_NONFINITE_STATE";
  }
  // A criterion that overflowed (or a load that is not finite) cannot be met honestly.
  if (result.converged && !std::isfinite(result.tolerance)) {
    result.converged = false;
    result.reason = "DIVERGED_NONFINITE_TOLERANCE";
  }
  // The factor allows CG's recursive residual to differ from the recomputed one by round-off.
  if (result.converged && result.residual_norm > 2 * result.tolerance) {
    result.converged = false;
    result.reason = "DIVERGED_RESIDUAL_ABOVE_TOLERANCE (PETSc: " + result.reason + ")";
  }
}

}  // namespace snede
