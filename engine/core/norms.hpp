// The Euclidean norm without overflow or underflow of the squares: forces of 1e155 N (a body
// in other units) have a finite norm, as BLAS's dnrm2 gives it.
#pragma once

#include <cmath>
#include <span>

namespace snede {

inline double euclidean_norm(std::span<const double> x) {
  double largest = 0;
  for (double v : x) largest = std::fmax(largest, std::fabs(v));  // fmax ignores NaN: checked below
  if (largest == 0 || !std::isfinite(largest)) {
    for (double v : x)
      if (!std::isfinite(v)) return std::isnan(v) ? v : INFINITY;
    return largest;
  }
  double sum = 0;
  for (double v : x) sum += (v / largest) * (v / largest);
  return largest * std::sqrt(sum);
}

}  // namespace snede
