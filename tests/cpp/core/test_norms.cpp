// euclidean_norm against a reference in long double with exact power-of-two scaling, at scales
// where the squares underflow, are ordinary, or overflow; NaN and infinity pass through.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/norms.hpp"

using snede::euclidean_norm;

namespace {

// Scaled by a power of two near the largest entry, so that the long-double squares are exact
// enough at every scale.
double reference_norm(const std::vector<double>& x) {
  double largest = 0;
  for (double v : x) largest = std::fmax(largest, std::fabs(v));
  if (largest == 0) return 0;
  const int exponent = std::ilogb(largest);
  long double sum = 0;
  for (double v : x) {
    const long double scaled = std::scalbn(static_cast<long double>(v), -exponent);
    sum += scaled * scaled;
  }
  return static_cast<double>(std::scalbn(std::sqrt(sum), exponent));
}

}  // namespace

TEST(EuclideanNorm, MatchesTheReferenceAtEveryScale) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  for (double scale : {1e-300, 1e-200, 1e-160, 1e-145, 1e-5, 1.0, 1e5, 1e145, 1e155, 1e200, 1e300})
    for (std::size_t n : {1u, 3u, 1000u}) {
      std::vector<double> x(n);
      for (double& v : x) v = scale * entry(random);
      const double expected = reference_norm(x);
      EXPECT_NEAR(euclidean_norm(x), expected, 1e-14 * expected) << "scale " << scale << ", n " << n;
    }
}

TEST(EuclideanNorm, MixedScalesKeepTheLargeEntries) {
  const std::vector<double> x{1e-170, 3e-160, 4.0, 1e-300, 3.0};
  EXPECT_DOUBLE_EQ(euclidean_norm(x), 5.0);
  const std::vector<double> y{1e200, 1e-200, 1e200};
  EXPECT_NEAR(euclidean_norm(y), std::sqrt(2.0) * 1e200, 1e-14 * 1e200);
}

TEST(EuclideanNorm, ZeroEmptyNanAndInfinity) {
  EXPECT_EQ(euclidean_norm(std::vector<double>{}), 0.0);
  EXPECT_EQ(euclidean_norm(std::vector<double>{0.0, -0.0}), 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isnan(euclidean_norm(std::vector<double>{1.0, nan, 2.0})));
  EXPECT_FALSE(std::isfinite(euclidean_norm(std::vector<double>{inf, nan})));
  EXPECT_EQ(euclidean_norm(std::vector<double>{1.0, -inf}), inf);
  EXPECT_EQ(euclidean_norm(std::vector<double>{1e300, 1e300}), std::sqrt(2.0) * 1e300);
}
