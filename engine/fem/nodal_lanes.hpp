// Moving nodal values between a (n_points, D) row-major array and batches: lane l of the
// batches belongs to the node whose row starts at rows[l] (= D·vertex; batch_width rows). A node's values are
// contiguous in the array but spread over D batches; with AVX (4 lanes) the (x, y) pair of a
// node moves as one 128-bit load or add and the lanes are transposed in registers, instead
// of moving 4·D doubles one by one (the gather and scatter of every element loop, §2.3).
// Only plain loads and stores: a lane that adds to the node the previous lane has just
// stored reads it back by store forwarding (masked stores defeat it, measured 2× slower).
#pragma once

#include <array>

#include "fem/batch.hpp"

namespace snede {

// values[k] lane l = nodal[rows[l] + k].
template <int D>
std::array<Batch, D> load_nodes(const double* nodal, const std::int32_t* rows) {
#if defined(__AVX__)
  if constexpr (batch_width == 4) {
    auto xy = [&](int lane) { return _mm_loadu_pd(nodal + rows[lane]); };
    const __m256d xy02 = _mm256_set_m128d(xy(2), xy(0)), xy13 = _mm256_set_m128d(xy(3), xy(1));
    const Batch x(Batch::Register(_mm256_unpacklo_pd(xy02, xy13))), y(Batch::Register(_mm256_unpackhi_pd(xy02, xy13)));
    if constexpr (D == 2)
      return {x, y};
    else
      return {x, y, Batch::gather(nodal + 2, rows)};
  }
#endif
  std::array<Batch, D> values;
  for (int k = 0; k < D; ++k) values[k] = Batch::gather(nodal + k, rows);
  return values;
}

// nodal[rows[l] + k] += values[k] lane l, for the lanes in `lanes`, lane after lane (lanes
// that share a node add in lane order).
template <int D>
void add_to_nodes(double* nodal, const std::int32_t* rows, const std::array<Batch, D>& values, LaneMask lanes) {
#if defined(__AVX__)
  if constexpr (batch_width == 4) {
    const __m256d x = __m256d(values[0].value()), y = __m256d(values[1].value());
    const __m256d xy02 = _mm256_unpacklo_pd(x, y), xy13 = _mm256_unpackhi_pd(x, y);  // (x0 y0 x2 y2), (x1 y1 x3 y3)
    const __m128d xy[4] = {_mm256_castpd256_pd128(xy02), _mm256_castpd256_pd128(xy13), _mm256_extractf128_pd(xy02, 1),
                           _mm256_extractf128_pd(xy13, 1)};
    auto add_lane = [&](int lane) {
      double* row = nodal + rows[lane];
      _mm_storeu_pd(row, _mm_add_pd(_mm_loadu_pd(row), xy[lane]));
      if constexpr (D == 3) row[2] += values[2][lane];
    };
    if (lanes == all_lanes) {  // the common case, without a branch per lane
      for (int lane = 0; lane < 4; ++lane) add_lane(lane);
    } else {
      for (int lane = 0; lane < 4; ++lane)
        if (lanes >> lane & 1) add_lane(lane);
    }
    return;
  }
#endif
  for (int lane = 0; lane < batch_width; ++lane)
    if (lanes >> lane & 1)
      for (int k = 0; k < D; ++k) nodal[rows[lane] + k] += values[k][lane];
}

}  // namespace snede
