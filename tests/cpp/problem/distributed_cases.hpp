// The distributed problem tests' case: a box (distributed_box.hpp) fixed at y = 0, sliding along
// an oblique line at x = 1, and a smooth deformation of it, by serial vertex ids.
#pragma once

#include <cmath>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"
#include "mesh/mesh.hpp"
#include "problem/distributed_static.hpp"

namespace snede::testing {

// Fixed at y = 0; sliding along an oblique line at x = 1 (not at y = 0); by serial ids.
inline DistributedConditions held_and_sliding(const Mesh& serial) {
  const int d = serial.dim();
  DistributedConditions conditions;
  for (VertexId v = 0; v < serial.n_points(); ++v) {
    const std::span<const double> x = serial.point(v);
    if (x[1] == 0) {
      conditions.fixed.push_back(v);
      conditions.fixed_values.insert(conditions.fixed_values.end(), static_cast<std::size_t>(d), 0.0);
    } else if (x[0] == 1) {
      conditions.sliding.push_back(v);
      for (int k = 0; k < d; ++k) conditions.sliding_directions.push_back(1.0 + k);
      conditions.sliding_anchors.insert(conditions.sliding_anchors.end(), static_cast<std::size_t>(d), 0.0);
    }
  }
  return conditions;
}

// A smooth deformation of the serial vertices, `amount` of the box's size.
inline std::vector<double> deformation(const Mesh& serial, double amount) {
  const int d = serial.dim();
  std::vector<double> u(static_cast<std::size_t>(serial.n_points()) * d);
  for (VertexId v = 0; v < serial.n_points(); ++v) {
    const std::span<const double> x = serial.point(v);
    for (int k = 0; k < d; ++k) u[static_cast<std::size_t>(v) * d + k] = amount * std::sin(2.0 * x[0] + k) * x[1];
  }
  return u;
}

inline double norm(Vec x) {
  double value = 0;
  SNEDE_PETSC(VecNorm(x, NORM_2, &value));
  return value;
}

}  // namespace snede::testing
