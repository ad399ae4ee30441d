// A double that counts its arithmetic: kernels templated on the scalar type are run once
// with Counted to obtain their exact flop count (the thesis's cost measure, Table 4.3:
// +, -, ×, / each one flop; sqrt, exp, log counted as one each and reported apart).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "core/double_like_scalar.hpp"

namespace snede {

struct FlopTally {
  std::int64_t arithmetic = 0;  // + - * /
  std::int64_t functions = 0;   // sqrt, exp, log
};

inline FlopTally& flop_tally() {
  thread_local FlopTally tally;
  return tally;
}

class Counted {
 public:
  Counted() = default;
  Counted(double v) : v_(v) {}  // NOLINT: implicit, like double
  double value() const { return v_; }

  friend Counted operator+(Counted a, Counted b) { return tick(a.v_ + b.v_); }
  friend Counted operator-(Counted a, Counted b) { return tick(a.v_ - b.v_); }
  friend Counted operator*(Counted a, Counted b) { return tick(a.v_ * b.v_); }
  friend Counted operator/(Counted a, Counted b) { return tick(a.v_ / b.v_); }
  friend Counted operator-(Counted a) { return Counted(-a.v_); }  // sign flip: free
  Counted& operator+=(Counted b) { return *this = *this + b; }
  Counted& operator-=(Counted b) { return *this = *this - b; }
  Counted& operator*=(Counted b) { return *this = *this * b; }
  Counted& operator/=(Counted b) { return *this = *this / b; }
  friend bool operator<(Counted a, Counted b) { return a.v_ < b.v_; }
  friend bool operator>(Counted a, Counted b) { return a.v_ > b.v_; }
  friend bool operator<=(Counted a, Counted b) { return a.v_ <= b.v_; }
  friend bool operator>=(Counted a, Counted b) { return a.v_ >= b.v_; }
  friend bool operator==(Counted a, Counted b) { return a.v_ == b.v_; }
  friend bool operator!=(Counted a, Counted b) { return a.v_ != b.v_; }

  friend Counted sqrt(Counted a) { return function(std::sqrt(a.v_)); }
  friend Counted exp(Counted a) { return function(std::exp(a.v_)); }
  friend Counted log(Counted a) { return function(std::log(a.v_)); }
  friend Counted abs(Counted a) { return Counted(std::abs(a.v_)); }
  friend bool isfinite(Counted a) { return std::isfinite(a.v_); }

 private:
  static Counted tick(double v) {
    ++flop_tally().arithmetic;
    return Counted(v);
  }
  static Counted function(double v) {
    ++flop_tally().functions;
    return Counted(v);
  }
  double v_ = 0;
};

inline double value_of(double x) { return x; }
inline double value_of(Counted x) { return x.value(); }

}  // namespace snede

namespace Eigen {
template <>
struct NumTraits<snede::Counted> : snede::DoubleLikeNumTraits<snede::Counted> {};
}  // namespace Eigen
