#include "solve/preconditioner_reuse.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace snede {

PreconditionerReuse::PreconditionerReuse(double refresh_ratio) : refresh_ratio_(refresh_ratio) {
  if (!(refresh_ratio == 0 || refresh_ratio >= 1) || !std::isfinite(refresh_ratio))
    throw std::invalid_argument("mg_refresh_ratio must be 0 (new levels for every solve) or at least 1 (CG "
                                "iterations per Newton iteration, over those of the solve that built the levels), got " +
                                std::to_string(refresh_ratio));
}

void PreconditionerReuse::record(int newton_iterations, int linear_iterations, bool converged, bool built_levels) {
  if (refresh_ratio_ == 0 || !converged) {
    stale_ = true;
    return;
  }
  if (newton_iterations == 0) return;  // already in equilibrium: nothing learnt about the levels
  const double per_newton = static_cast<double>(linear_iterations) / newton_iterations;
  if (built_levels) {
    baseline_ = std::max(per_newton, 1.0);
    stale_ = false;
  } else {
    stale_ = stale_ || per_newton > refresh_ratio_ * baseline_;
  }
}

}  // namespace snede
