// Several elements at once: a scalar that holds the same quantity for `batch_width` elements
// in one SIMD register. The element kernels and materials are templated on the scalar (they
// also run on Counted), so on Batch they evaluate batch_width elements per call with the
// same formulas, each lane rounding exactly as a double would (§2.3, §4.3; the DESIGN's
// "hot loops stream"). Lanes never mix: there is no reduction across lanes here.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <utility>

#if defined(__AVX__) || defined(__SSE2__)
#include <immintrin.h>
#endif

#include "core/double_like_scalar.hpp"

namespace snede {

// Doubles per register on the target: 4 with AVX (256 bits), else 2 (SSE2, the portable
// x86-64 baseline, or the compiler's generic vectors elsewhere). AVX-512's 8 lanes are not
// used: on the development machine (AMD Zen 4, which runs them as two 256-bit halves) every
// loop was slower with them (linear tangent 10.8 against 7.6 ns per tetrahedron).
#if defined(__AVX__)
inline constexpr int batch_width = 4;
#else
inline constexpr int batch_width = 2;
#endif

// Bit l set: lane l.
using LaneMask = std::uint32_t;
inline constexpr LaneMask all_lanes = (LaneMask{1} << batch_width) - 1;

// batch_width int32 indices in one register.
using LaneIndices = std::int32_t __attribute__((vector_size(batch_width * sizeof(std::int32_t))));

// The mask of a vector comparison's lanes that hold true (all bits set): the sign bits,
// gathered by one movemask instruction where there is one for the lanes' size.
template <class Comparison>
LaneMask true_lanes(Comparison lanes) {
  constexpr std::size_t lane_bytes = sizeof(lanes[0]), bytes = sizeof(Comparison);
#if defined(__AVX__)
  if constexpr (lane_bytes == 8 && bytes == 32) return static_cast<LaneMask>(_mm256_movemask_pd(__m256d(lanes)));
#endif
#if defined(__SSE2__)
  if constexpr (lane_bytes == 8 && bytes == 16) return static_cast<LaneMask>(_mm_movemask_pd(__m128d(lanes)));
  if constexpr (lane_bytes == 4 && bytes == 16) return static_cast<LaneMask>(_mm_movemask_ps(__m128(lanes)));
#endif
  LaneMask mask = 0;
  for (int lane = 0; lane < batch_width; ++lane)
    if (lanes[lane]) mask |= LaneMask{1} << lane;
  return mask;
}

class Batch {
 public:
  using Register = double __attribute__((vector_size(batch_width * sizeof(double))));

  Batch() = default;
  Batch(double x) : v_(Register{} + x) {}  // NOLINT: implicit, like double (every lane x)
  explicit Batch(Register v) : v_(v) {}

  // The batch whose lane l is lane_value(l).
  template <class LaneValue>
  static Batch from_lanes(LaneValue&& lane_value) {
    return from_lanes(lane_value, std::make_index_sequence<batch_width>{});
  }

  // batch_width doubles from memory (no alignment required).
  static Batch load(const double* values) {
    Register v;
    std::memcpy(&v, values, sizeof v);
    return Batch(v);
  }

  // Lane l is values[indices[l]] (batch_width indices).
  static Batch gather(const double* values, const std::int32_t* indices) {
    return from_lanes([&](int lane) { return values[indices[lane]]; });
  }

  double operator[](int lane) const { return v_[lane]; }
  Register value() const { return v_; }

  friend Batch operator+(Batch a, Batch b) { return Batch(a.v_ + b.v_); }
  friend Batch operator-(Batch a, Batch b) { return Batch(a.v_ - b.v_); }
  friend Batch operator*(Batch a, Batch b) { return Batch(a.v_ * b.v_); }
  friend Batch operator/(Batch a, Batch b) { return Batch(a.v_ / b.v_); }
  friend Batch operator-(Batch a) { return Batch(-a.v_); }
  Batch& operator+=(Batch b) { return *this = *this + b; }
  Batch& operator-=(Batch b) { return *this = *this - b; }
  Batch& operator*=(Batch b) { return *this = *this * b; }
  Batch& operator/=(Batch b) { return *this = *this / b; }

  // Correctly rounded per lane, as std::sqrt.
  friend Batch sqrt(Batch a) {
#if defined(__AVX__)
    return Batch(Register(_mm256_sqrt_pd(__m256d(a.v_))));
#elif defined(__SSE2__)
    return Batch(Register(_mm_sqrt_pd(__m128d(a.v_))));
#else
    return from_lanes([&](int lane) { return std::sqrt(a[lane]); });
#endif
  }
  // libm's exp and log lane by lane: bit for bit the scalar kernels' values.
  friend Batch exp(Batch a) {
    return from_lanes([&](int lane) { return std::exp(a[lane]); });
  }
  friend Batch log(Batch a) {
    return from_lanes([&](int lane) { return std::log(a[lane]); });
  }

  // Lanes with a ≤ 0 (not NaN ones, as for a double).
  friend LaneMask non_positive_lanes(Batch a) { return true_lanes(a.v_ <= 0.0); }
  // Lanes neither infinite nor NaN.
  friend LaneMask finite_lanes(Batch a) { return true_lanes(a.v_ * 0.0 == 0.0); }

 private:
  template <class LaneValue, std::size_t... lane>
  static Batch from_lanes(LaneValue& lane_value, std::index_sequence<lane...>) {
    return Batch(Register{lane_value(static_cast<int>(lane))...});
  }

  Register v_{};
};

// Lane `lane` of every entry of a tensor of batches.
template <class Derived>
auto lane_of(const Eigen::MatrixBase<Derived>& batches, int lane) {
  return batches.unaryExpr([lane](const Batch& b) { return b[lane]; }).eval();
}

// Lanes in which every entry of a tensor of batches is finite: x·0 is 0 for finite x and NaN
// otherwise, and a NaN survives the sum.
template <class Derived>
LaneMask finite_lanes(const Eigen::MatrixBase<Derived>& batches) {
  Batch probe = 0.0;
  for (Eigen::Index j = 0; j < batches.cols(); ++j)
    for (Eigen::Index i = 0; i < batches.rows(); ++i) probe += batches(i, j) * 0.0;
  return finite_lanes(probe);
}

// True if no entry of x is infinite or NaN.
inline bool all_finite(std::span<const double> x) {
  Batch probe = 0.0;
  std::size_t i = 0;
  for (; i + batch_width <= x.size(); i += batch_width) probe += Batch::load(x.data() + i) * 0.0;
  for (; i < x.size(); ++i)
    if (!std::isfinite(x[i])) return false;
  return finite_lanes(probe) == all_lanes;
}

}  // namespace snede

namespace Eigen {
template <>
struct NumTraits<snede::Batch> : snede::DoubleLikeNumTraits<snede::Batch> {};
}  // namespace Eigen
