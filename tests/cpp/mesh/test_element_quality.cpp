#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mesh/element_quality.hpp"

using snede::element_quality;

TEST(ElementQuality, RegularTetrahedron) {
  // vertices of a regular tetrahedron with edge 2√2
  const std::vector<double> x{1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
  const auto q = element_quality(3, x);
  const double edge = 2 * std::sqrt(2.0);
  EXPECT_NEAR(std::abs(q.volume), edge * edge * edge / (6 * std::sqrt(2.0)), 1e-13);
  EXPECT_NEAR(q.aspect_ratio, std::sqrt(2.0 / 3.0), 1e-14);
  EXPECT_NEAR(q.min_dihedral, std::acos(1.0 / 3.0), 1e-14);
  EXPECT_NEAR(q.max_dihedral, std::acos(1.0 / 3.0), 1e-14);
}

TEST(ElementQuality, KuhnTetrahedronAndRightTriangle) {
  // 0 -> e0 -> e0+e1 -> e0+e1+e2: volume 1/6, dihedral angles 45°, 60° and 90°
  const std::vector<double> x{0, 0, 0, 1, 0, 0, 1, 1, 0, 1, 1, 1};
  const auto q = element_quality(3, x);
  EXPECT_NEAR(q.volume, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(q.min_dihedral, std::numbers::pi / 4, 1e-14);
  EXPECT_NEAR(q.max_dihedral, std::numbers::pi / 2, 1e-14);
  // minimum height: from vertex 0 to face (1,0,0),(1,1,0),(1,1,1) is 1? no: smallest height is
  // 3V / largest face area = 0.5 / (√2/2) = 1/√2; longest edge √3.
  EXPECT_NEAR(q.aspect_ratio, (1 / std::sqrt(2.0)) / std::sqrt(3.0), 1e-14);
  const std::vector<double> t{0, 0, 2, 0, 0, 1};
  const auto r = element_quality(2, t);
  EXPECT_NEAR(r.volume, 1.0, 1e-15);
  EXPECT_NEAR(r.max_dihedral, std::numbers::pi / 2, 1e-14);
  EXPECT_NEAR(r.min_dihedral, std::atan(0.5), 1e-14);
  EXPECT_NEAR(r.aspect_ratio, (2.0 / std::sqrt(5.0)) / std::sqrt(5.0), 1e-14);
}

TEST(ElementQuality, OrientationGivesTheSignOfTheVolume) {
  const std::vector<double> x{0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};  // two vertices swapped
  EXPECT_NEAR(element_quality(3, x).volume, -1.0 / 6.0, 1e-15);
  EXPECT_THROW(element_quality(4, x), std::invalid_argument);
  EXPECT_THROW(element_quality(3, std::vector<double>(5)), std::invalid_argument);
}

TEST(ElementQuality, InscribedDiameter) {
  // regular tetrahedron of edge a: inradius a/√24; right triangle with legs 2, 1: r = (2 + 1 − √5)/2
  const std::vector<double> x{1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
  EXPECT_NEAR(element_quality(3, x).inscribed_diameter, 2 * 2 * std::sqrt(2.0) / std::sqrt(24.0), 1e-14);
  const std::vector<double> t{0, 0, 2, 0, 0, 1};
  EXPECT_NEAR(element_quality(2, t).inscribed_diameter, 3 - std::sqrt(5.0), 1e-14);
}
