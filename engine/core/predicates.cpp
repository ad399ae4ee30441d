#include "core/predicates.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace snede {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point2 = Kernel::Point_2;
using Point3 = Kernel::Point_3;

Point2 point_2(const double* p) { return {p[0], p[1]}; }
Point3 point_3(const double* p) { return {p[0], p[1], p[2]}; }

}  // namespace

int orientation_2d(const double* a, const double* b, const double* c) {
  return CGAL::orientation(point_2(a), point_2(b), point_2(c));
}

int orientation_3d(const double* a, const double* b, const double* c, const double* d) {
  return CGAL::orientation(point_3(a), point_3(b), point_3(c), point_3(d));
}

int in_circle(const double* a, const double* b, const double* c, const double* d) {
  return CGAL::side_of_oriented_circle(point_2(a), point_2(b), point_2(c), point_2(d));
}

int in_sphere(const double* a, const double* b, const double* c, const double* d, const double* e) {
  return CGAL::side_of_oriented_sphere(point_3(a), point_3(b), point_3(c), point_3(d), point_3(e));
}

bool collinear_3d(const double* a, const double* b, const double* c) {
  return CGAL::collinear(point_3(a), point_3(b), point_3(c));
}

}  // namespace snede
