// How far constraints stop a piece's rigid motions (§3.3; piece_holding.hpp): the rows
// (I − P_v) R_v of its constrained vertices, R_v = [I | −[x_v]×] the infinitesimal rigid motions
// at x_v, accumulated as the Gram matrix Σ Rᵀ(I − P)R about an origin among the vertices, and
// its rank. Shared by the serial check and the one on MPI ranks, which sums the Grams of a
// piece's parts over the ranks (about one origin, so that they add up).
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include <Eigen/Dense>

namespace snede {

struct RigidMotionGram {
  explicit RigidMotionGram(int dim);

  Eigen::MatrixXd gram;  // n_motions × n_motions: 3 in 2D, 6 in 3D
  std::array<double, 3> origin{0, 0, 0};
  bool has_origin = false;  // else the first vertex added becomes the origin
  double span = 0;          // largest |x − origin| over its constrained vertices: the rotations' scale
  std::size_t components = 0;

  // A vertex at `point` whose constraints' projection block is `projection` (dim × dim,
  // row-major) and which has `constrained_components` of them (0: nothing is added).
  void add(std::span<const double> point, std::span<const double> projection, std::size_t constrained_components);
  // The rank of the rows: rotations scaled by 1/span so that every entry is O(1); the
  // eigenvalues of a direction the rows do not constrain are then rounding, O(1e-16) relative,
  // and 1e-10 leaves six orders of margin (it counts as a hinge a set of vertices off a line by
  // less than 1e-5 of their span, which holds the piece no better numerically).
  std::size_t rank() const;

 private:
  int dim_;
};

}  // namespace snede
