// Eigen's description of a scalar type that stands in for double in templated kernels
// (Counted counts its flops, Batch holds several elements' values): real, signed, one
// operation per arithmetic operator. Each such type's NumTraits derives from this.
#pragma once

#include <Eigen/Core>

namespace snede {

template <class Scalar>
struct DoubleLikeNumTraits : Eigen::NumTraits<double> {
  using Real = Scalar;
  using NonInteger = Scalar;
  using Nested = Scalar;
  using Literal = Scalar;
  enum { IsComplex = 0, IsInteger = 0, IsSigned = 1, RequireInitialization = 1, ReadCost = 1, AddCost = 1, MulCost = 1 };
};

}  // namespace snede
