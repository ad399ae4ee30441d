#include "solvers/static_options.hpp"

#include <cmath>
#include <stdexcept>

#include "core/rank_agreement.hpp"

namespace snede {

StaticOptions distributed_solve_options() {
  StaticOptions options;
  options.method = StaticMethod::linear_cg;
  options.stopping.rtol = 1e-8;
  options.stopping.criterion = StoppingCriterion::relative;
  options.preconditioner = "none";
  options.options_prefix = "dstatic_";
  return options;
}

void require_valid(const StaticOptions& options, bool linear_material, MPI_Comm comm) {
  InputDigest petsc_options;
  for (const auto& [name, value] : options.petsc_options) petsc_options.add(name).add(value);
  RankAgreement("StaticSolver")
      .input("method", static_cast<double>(options.method))
      .input("criterion", static_cast<double>(options.stopping.criterion))
      .input("rtol", options.stopping.rtol)
      .input("round_tolerance", options.stopping.round_tolerance)
      .input("max_iterations", options.max_iterations)
      .input("options_prefix", options.options_prefix)
      .input("preconditioner", options.preconditioner)
      .input("petsc_options", petsc_options)
      .require(comm);
  const StoppingRule& stopping = options.stopping;
  if (stopping.rtol <= 0 || !std::isfinite(stopping.rtol))
    throw std::invalid_argument("rtol must be positive, got " + std::to_string(stopping.rtol));
  if (!(stopping.round_tolerance >= 0) || !std::isfinite(stopping.round_tolerance))
    throw std::invalid_argument("round_tolerance must be finite and non-negative, got " +
                                std::to_string(stopping.round_tolerance));
  if (stopping.criterion == StoppingCriterion::relative && !(stopping.rtol < 1))
    throw std::invalid_argument("a relative rtol must be below 1, got " + std::to_string(stopping.rtol));
  if (options.max_iterations < 1)
    throw std::invalid_argument("max_iterations must be at least 1, got " + std::to_string(options.max_iterations));
  if (options.method == StaticMethod::linear_cg && !linear_material)
    throw std::invalid_argument(
        "method 'cg' (linear CG) solves the linear problem and needs LinearElastic; use 'ncg' or 'newton' for "
        "nonlinear materials");
}

}  // namespace snede
