// Points and vectors in space as three doubles, with the few operations the geometric code
// needs (sweeps, needle queries, surface cutting). In 2D code the third component is 0.
#pragma once

#include <array>
#include <cmath>

namespace snede {

using Point3 = std::array<double, 3>;

inline Point3 minus(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
// a + s d
inline Point3 plus_scaled(const Point3& a, double s, const Point3& d) {
  return {a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]};
}
// (1 − t) a + t b, computed as a + t (b − a)
inline Point3 lerp(const Point3& a, const Point3& b, double t) { return plus_scaled(a, t, minus(b, a)); }
inline double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Point3& a) { return std::sqrt(dot(a, a)); }
inline double distance(const Point3& a, const Point3& b) { return norm(minus(a, b)); }

}  // namespace snede
