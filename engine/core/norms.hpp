// The Euclidean norm without overflow or underflow of the squares: forces of 1e155 N (a body
// in other units) have a finite norm, as BLAS's dnrm2 gives it.
#pragma once

#include <cmath>
#include <span>

namespace snede {

inline double euclidean_norm(std::span<const double> x) {
  // One pass of plain squares where they neither overflow nor underflow: what a needle's
  // update evaluates every solve (the scaled pass cost a tenth of a 2D update, issue 33).
  // A square below 1e-280 next to a sum above it changes nothing.
  double squares = 0;
  for (double v : x) squares += v * v;
  if (squares >= 1e-280 && squares <= 1e280) return std::sqrt(squares);
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
