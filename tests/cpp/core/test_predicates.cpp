// The predicates are checked against the textbook determinants evaluated exactly in rational
// arithmetic (GMP, not CGAL's filtered predicates) and, near circles and spheres, against the
// exact distance to the known centre, on inputs within an ulp of degeneracy — where the same
// determinants evaluated in double are shown to give wrong signs.
#include <gtest/gtest.h>

#include <CGAL/Exact_rational.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <random>

#include "core/predicates.hpp"
#include "mesh/element_quality.hpp"

namespace {

using Exact = CGAL::Exact_rational;
using P2 = std::array<double, 2>;
using P3 = std::array<double, 3>;

int sign_of(double v) { return (v > 0) - (v < 0); }
int sign_of(const Exact& v) { return CGAL::sign(v); }

// Determinant by Laplace expansion along the first row.
template <class T, std::size_t N>
T det(const std::array<std::array<T, N>, N>& m) {
  if constexpr (N == 1) {
    return m[0][0];
  } else {
    T sum(0);
    for (std::size_t j = 0; j < N; ++j) {
      std::array<std::array<T, N - 1>, N - 1> minor;
      for (std::size_t i = 1; i < N; ++i)
        for (std::size_t k = 0, c = 0; k < N; ++k)
          if (k != j) minor[i - 1][c++] = m[i][k];
      const T term = m[0][j] * det(minor);
      if (j % 2)
        sum -= term;
      else
        sum += term;
    }
    return sum;
  }
}

// p − o, and p − o with |p − o|² appended (the lifting of the in-circle/in-sphere tests).
template <class T, std::size_t D>
std::array<T, D> difference(const std::array<double, D>& p, const std::array<double, D>& o) {
  std::array<T, D> r;
  for (std::size_t i = 0; i < D; ++i) r[i] = T(p[i]) - T(o[i]);
  return r;
}
template <class T, std::size_t D>
std::array<T, D + 1> lifted(const std::array<double, D>& p, const std::array<double, D>& o) {
  std::array<T, D + 1> r;
  r[D] = T(0);
  for (std::size_t i = 0; i < D; ++i) {
    r[i] = T(p[i]) - T(o[i]);
    r[D] = r[D] + r[i] * r[i];
  }
  return r;
}

template <class T>
T orientation_2d_det(const P2& a, const P2& b, const P2& c) {
  return det<T, 2>({difference<T>(b, a), difference<T>(c, a)});
}
template <class T>
T orientation_3d_det(const P3& a, const P3& b, const P3& c, const P3& d) {
  return det<T, 3>({difference<T>(b, a), difference<T>(c, a), difference<T>(d, a)});
}
// Positive when d is inside the circle through counter-clockwise a, b, c.
template <class T>
T in_circle_det(const P2& a, const P2& b, const P2& c, const P2& d) {
  return det<T, 3>({lifted<T>(a, d), lifted<T>(b, d), lifted<T>(c, d)});
}
// Negated so that it is positive when e is inside the sphere through a, b, c, d with
// orientation_3d_det(a, b, c, d) > 0.
template <class T>
T in_sphere_det(const P3& a, const P3& b, const P3& c, const P3& d, const P3& e) {
  return -det<T, 4>({lifted<T>(a, e), lifted<T>(b, e), lifted<T>(c, e), lifted<T>(d, e)});
}

// Sign of r² − |p|²: +1 inside the origin-centred circle or sphere of radius r.
template <std::size_t D>
int inside_centred_ball(const std::array<double, D>& p, double r) {
  Exact squared(0);
  for (double x : p) squared = squared + Exact(x) * Exact(x);
  return sign_of(Exact(r) * Exact(r) - squared);
}

double up(double x) { return std::nextafter(x, INFINITY); }
double down(double x) { return std::nextafter(x, -INFINITY); }

TEST(Predicates, Orientation2dConvention) {
  const P2 a{0, 0}, b{1, 0}, c{0, 1}, on_line{2, 0};
  EXPECT_EQ(snede::orientation_2d(a.data(), b.data(), c.data()), 1);
  EXPECT_EQ(snede::orientation_2d(a.data(), c.data(), b.data()), -1);
  EXPECT_EQ(snede::orientation_2d(a.data(), b.data(), on_line.data()), 0);
}

// Kettner et al., "Classroom examples of robustness problems in geometric computations":
// p is an ulp-scale perturbation of a point on the line through q and r.
TEST(Predicates, Orientation2dExactWhereDoubleDeterminantFails) {
  const double ulp = std::ldexp(1.0, -53);  // of numbers in [0.5, 1)
  const P2 q{12, 12}, r{24, 24};
  int n_wrong_sign = 0, n_false_zero = 0;
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 64; ++j) {
      const P2 p{0.5 + i * ulp, 0.5 + j * ulp};
      const int exact = sign_of(orientation_2d_det<Exact>(p, q, r));
      const int naive = sign_of(orientation_2d_det<double>(p, q, r));
      ASSERT_EQ(snede::orientation_2d(p.data(), q.data(), r.data()), exact) << i << ", " << j;
      ASSERT_EQ(exact, i == j ? 0 : (j > i ? 1 : -1));  // above the line y = x: counter-clockwise
      n_wrong_sign += naive == -exact && exact != 0;
      n_false_zero += naive == 0 && exact != 0;
    }
  }
  EXPECT_GT(n_wrong_sign, 0);
  EXPECT_GT(n_false_zero, 0);
}

TEST(Predicates, Orientation3dConventionIsSignedVolume) {
  const P3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0}, d{0, 0, 1};
  ASSERT_EQ(orientation_3d_det<double>(a, b, c, d), 1.0);
  EXPECT_EQ(snede::orientation_3d(a.data(), b.data(), c.data(), d.data()), 1);
  EXPECT_EQ(snede::orientation_3d(a.data(), c.data(), b.data(), d.data()), -1);

  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  auto point = [&] { return P3{coordinate(rng), coordinate(rng), coordinate(rng)}; };
  for (int k = 0; k < 100; ++k) {
    const P3 p = point(), q = point(), r = point(), s = point();
    const int orientation = snede::orientation_3d(p.data(), q.data(), r.data(), s.data());
    EXPECT_EQ(orientation, sign_of(orientation_3d_det<Exact>(p, q, r, s)));
    // the mesh's convention: a positively oriented tetrahedron has positive volume
    const std::array<double, 12> corners{p[0], p[1], p[2], q[0], q[1], q[2], r[0], r[1], r[2], s[0], s[1], s[2]};
    EXPECT_EQ(orientation, sign_of(snede::signed_volume(3, corners)));
  }
}

// Points on the slanted plane z = x/2 + y/4 + 1/8 (exactly representable), then the last
// one moved by an ulp in each coordinate; and points rounded onto a random plane.
TEST(Predicates, Orientation3dExactNearCoplanar) {
  const auto on_plane = [](double x, double y) { return P3{x, y, x / 2 + y / 4 + 0.125}; };
  const P3 a = on_plane(0.75, 3), b = on_plane(-5, 1.5), c = on_plane(9, -7), d = on_plane(0.3125, 2.5);
  EXPECT_EQ(snede::orientation_3d(a.data(), b.data(), c.data(), d.data()), 0);
  for (int i = 0; i < 3; ++i) {
    for (double (*move)(double) : {up, down}) {
      P3 moved = d;
      moved[i] = move(moved[i]);
      const int exact = sign_of(orientation_3d_det<Exact>(a, b, c, moved));
      ASSERT_NE(exact, 0);
      EXPECT_EQ(snede::orientation_3d(a.data(), b.data(), c.data(), moved.data()), exact);
    }
  }

  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(-1, 1);
  auto point = [&] { return P3{uniform(rng), uniform(rng), uniform(rng)}; };
  for (int k = 0; k < 1000; ++k) {
    const P3 p = point(), q = point(), r = point();
    const double s = uniform(rng), t = uniform(rng);
    P3 near;  // p + s (q − p) + t (r − p), rounded
    for (int i = 0; i < 3; ++i) near[i] = p[i] + s * (q[i] - p[i]) + t * (r[i] - p[i]);
    ASSERT_EQ(snede::orientation_3d(p.data(), q.data(), r.data(), near.data()),
              sign_of(orientation_3d_det<Exact>(p, q, r, near)));
  }
}

TEST(Predicates, InCircleCocircularAndOneUlpOff) {
  const P2 a{1, 0}, b{0, 1}, c{-1, 0}, d{0, -1};
  EXPECT_EQ(snede::in_circle(a.data(), b.data(), c.data(), d.data()), 0);
  for (double y : {up(-1.0), down(-1.0)}) {
    const P2 e{0, y};
    const int inside = inside_centred_ball(e, 1);
    ASSERT_EQ(inside, y > -1 ? 1 : -1);
    ASSERT_EQ(sign_of(in_circle_det<Exact>(a, b, c, e)), inside);
    EXPECT_EQ(snede::in_circle(a.data(), b.data(), c.data(), e.data()), inside);
    EXPECT_EQ(snede::in_circle(a.data(), c.data(), b.data(), e.data()), -inside);  // clockwise
  }
}

// Points rounded onto the unit circle: inside or outside by less than an ulp.
TEST(Predicates, InCircleExactWhereDoubleDeterminantFails) {
  const P2 a{1, 0}, b{0, 1}, c{-1, 0};
  int n_naive_wrong = 0;
  for (int k = 1; k < 1000; ++k) {
    const double x = k / 1000.0;
    const P2 d{x, -std::sqrt(1 - x * x)};
    const int inside = inside_centred_ball(d, 1);
    ASSERT_EQ(sign_of(in_circle_det<Exact>(a, b, c, d)), inside);
    ASSERT_EQ(snede::in_circle(a.data(), b.data(), c.data(), d.data()), inside) << x;
    n_naive_wrong += sign_of(in_circle_det<double>(a, b, c, d)) != inside;
  }
  EXPECT_GT(n_naive_wrong, 0);
}

TEST(Predicates, InSphereCosphericalAndOneUlpOff) {
  const P3 a{0, 1, 0}, b{1, 0, 0}, c{0, 0, 1}, d{-1, 0, 0}, e{0, 0, -1};
  ASSERT_GT(orientation_3d_det<double>(a, b, c, d), 0);
  ASSERT_EQ(snede::orientation_3d(a.data(), b.data(), c.data(), d.data()), 1);
  EXPECT_EQ(snede::in_sphere(a.data(), b.data(), c.data(), d.data(), e.data()), 0);
  const P3 centre{0, 0, 0}, far{0, 0, 3};
  EXPECT_EQ(snede::in_sphere(a.data(), b.data(), c.data(), d.data(), centre.data()), 1);
  EXPECT_EQ(snede::in_sphere(a.data(), b.data(), c.data(), d.data(), far.data()), -1);
  for (double z : {up(-1.0), down(-1.0)}) {
    const P3 f{0, 0, z};
    const int inside = inside_centred_ball(f, 1);
    ASSERT_EQ(inside, z > -1 ? 1 : -1);
    ASSERT_EQ(sign_of(in_sphere_det<Exact>(a, b, c, d, f)), inside);
    EXPECT_EQ(snede::in_sphere(a.data(), b.data(), c.data(), d.data(), f.data()), inside);
    EXPECT_EQ(snede::in_sphere(b.data(), a.data(), c.data(), d.data(), f.data()), -inside);  // negatively oriented
  }
}

// Points rounded onto the unit sphere.
TEST(Predicates, InSphereExactWhereDoubleDeterminantFails) {
  const P3 a{0, 1, 0}, b{1, 0, 0}, c{0, 0, 1}, d{-1, 0, 0};
  int n_naive_wrong = 0;
  for (int i = 1; i < 40; ++i) {
    for (int j = 1; j < 40; ++j) {
      const double x = i / 100.0, y = j / 100.0;
      const P3 e{x, y, -std::sqrt(1 - x * x - y * y)};
      const int inside = inside_centred_ball(e, 1);
      ASSERT_EQ(sign_of(in_sphere_det<Exact>(a, b, c, d, e)), inside);
      ASSERT_EQ(snede::in_sphere(a.data(), b.data(), c.data(), d.data(), e.data()), inside) << x << ", " << y;
      n_naive_wrong += sign_of(in_sphere_det<double>(a, b, c, d, e)) != inside;
    }
  }
  EXPECT_GT(n_naive_wrong, 0);
}

// a, a + v, a + 2v exactly, then c moved by an ulp; and points on random lines, exactly or
// rounded, checked against an exactly zero cross product.
TEST(Predicates, Collinear3dExact) {
  const P3 a{0.625, -2.5, 7}, v{0.375, 1.25, -0.5};
  const P3 b{a[0] + v[0], a[1] + v[1], a[2] + v[2]}, c{a[0] + 2 * v[0], a[1] + 2 * v[1], a[2] + 2 * v[2]};
  const auto exactly_collinear = [](const P3& p, const P3& q, const P3& r) {
    const auto u = difference<Exact>(q, p), w = difference<Exact>(r, p);
    return u[1] * w[2] == u[2] * w[1] && u[2] * w[0] == u[0] * w[2] && u[0] * w[1] == u[1] * w[0];
  };
  ASSERT_TRUE(exactly_collinear(a, b, c));
  EXPECT_TRUE(snede::collinear_3d(a.data(), b.data(), c.data()));
  for (int i = 0; i < 3; ++i) {
    P3 moved = c;
    moved[i] = up(moved[i]);
    ASSERT_FALSE(exactly_collinear(a, b, moved));
    EXPECT_FALSE(snede::collinear_3d(a.data(), b.data(), moved.data()));
  }

  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> grid(-1024, 1024);
  std::uniform_real_distribution<double> uniform(-2, 2);
  auto grid_point = [&] { return P3{grid(rng) / 1024.0, grid(rng) / 1024.0, grid(rng) / 1024.0}; };
  int n_collinear = 0;
  for (int k = 0; k < 1000; ++k) {
    const P3 p = grid_point(), q = grid_point();
    const double t = k % 2 ? uniform(rng) : (k % 32) / 16.0;  // exact on the 2^-10 grid for even k
    const P3 r{p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2])};
    const bool collinear = exactly_collinear(p, q, r);
    ASSERT_EQ(snede::collinear_3d(p.data(), q.data(), r.data()), collinear);
    n_collinear += collinear;
  }
  EXPECT_GE(n_collinear, 500);
}

}  // namespace
