#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "core/counted.hpp"

using snede::Counted;
using snede::flop_tally;

TEST(Counted, CountsArithmeticAndFunctionsSeparately) {
  flop_tally() = {};
  Counted a(2.0), b(3.0);
  const Counted c = a * b + a / b - b;  // 4 flops
  EXPECT_DOUBLE_EQ(c.value(), 2.0 * 3.0 + 2.0 / 3.0 - 3.0);
  EXPECT_EQ(flop_tally().arithmetic, 4);
  const Counted d = sqrt(c) + exp(a) - log(b);  // 2 flops, 3 functions
  EXPECT_DOUBLE_EQ(d.value(), std::sqrt(c.value()) + std::exp(2.0) - std::log(3.0));
  EXPECT_EQ(flop_tally().arithmetic, 6);
  EXPECT_EQ(flop_tally().functions, 3);
}

TEST(Counted, WorksInsideEigen) {
  flop_tally() = {};
  Eigen::Matrix<Counted, 3, 3> m;
  m << 2, 0, 0, 0, 3, 0, 0, 0, 4;
  EXPECT_DOUBLE_EQ(m.determinant().value(), 24.0);
  EXPECT_GT(flop_tally().arithmetic, 0);
}
