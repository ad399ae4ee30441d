#include "solvers/solve_result.hpp"

#include "core/formatted.hpp"

namespace snede {

std::string summary(const SolveResult& r) {
  std::string line = (r.converged ? "converged (" : "NOT converged (") + r.reason + ") after " +
                     std::to_string(r.iterations) + " iterations";
  if (r.linear_iterations) line += " (" + std::to_string(r.linear_iterations) + " linear)";
  return line + formatted(": |r| = %.3e (tolerance %.3e), energy %.6e J, %.3f s, %.1f MFLOP", r.residual_norm,
                          r.tolerance, r.energy, r.seconds, r.flops / 1e6);
}

}  // namespace snede
