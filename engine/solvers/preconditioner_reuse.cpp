#include "solvers/preconditioner_reuse.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace snede {

PreconditionerReuse::PreconditionerReuse(double refresh_ratio) : refresh_ratio_(refresh_ratio) {
  if (!(refresh_ratio == 0 || refresh_ratio >= 1) || !std::isfinite(refresh_ratio))
    throw std::invalid_argument("mg_refresh_ratio must be 0 (new levels for every solve) or at least 1 (CG "
                                "iterations per Newton iteration, over those of the first Newton iteration "
                                "after the levels were filled), got " +
                                std::to_string(refresh_ratio));
}

void PreconditionerReuse::filled(bool new_baseline) {
  stale_ = false;
  awaiting_baseline_ = awaiting_baseline_ || new_baseline || baseline_ == 0;
}

void PreconditionerReuse::record_linear_solve(int iterations, bool converged) {
  if (!converged) {
    stale_ = true;
    return;
  }
  if (awaiting_baseline_) {
    baseline_ = std::max(iterations, 1);
    awaiting_baseline_ = false;
    return;
  }
  if (refresh_ratio_ > 0) stale_ = stale_ || iterations > refresh_ratio_ * baseline_;
}

void PreconditionerReuse::record_solve(bool converged) {
  if (refresh_ratio_ == 0 || !converged) stale_ = true;
}

}  // namespace snede
