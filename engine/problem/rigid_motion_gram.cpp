#include "problem/rigid_motion_gram.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace snede {
namespace {

// The rigid motions' values at x (relative to the piece's origin), (dim × n_motions) row-major
// into `rows`: translations, then rotations, u = a + ω × x = a − [x]× ω (3D) or a + ω (−y, x) (2D).
void rigid_motions_at(std::span<const double> x, int dim, std::span<double> rows) {
  const int n = dim == 3 ? 6 : 3;
  std::fill(rows.begin(), rows.end(), 0.0);
  for (int k = 0; k < dim; ++k) rows[k * n + k] = 1;
  if (dim == 2) {
    rows[0 * n + 2] = -x[1];
    rows[1 * n + 2] = x[0];
    return;
  }
  // −[x]× in columns 3–5: (x × ω)_i = ε_ijk x_j ω_k, negated.
  rows[0 * n + 4] = x[2], rows[0 * n + 5] = -x[1];
  rows[1 * n + 3] = -x[2], rows[1 * n + 5] = x[0];
  rows[2 * n + 3] = x[1], rows[2 * n + 4] = -x[0];
}

}  // namespace

RigidMotionGram::RigidMotionGram(int dim)
    : gram(Eigen::MatrixXd::Zero(dim == 3 ? 6 : 3, dim == 3 ? 6 : 3)), dim_(dim) {}

void RigidMotionGram::add(std::span<const double> point, std::span<const double> projection,
                          std::size_t constrained_components) {
  if (constrained_components == 0) return;
  const int n_motions = static_cast<int>(gram.rows());
  if (!has_origin) {
    for (int k = 0; k < dim_; ++k) origin[k] = point[k];
    has_origin = true;
  }
  std::array<double, 3> x{0, 0, 0};
  for (int k = 0; k < dim_; ++k) x[k] = point[k] - origin[k];
  span = std::max(span, std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]));
  components += constrained_components;
  std::vector<double> rows(static_cast<std::size_t>(dim_ * n_motions));
  rigid_motions_at(x, dim_, rows);
  Eigen::MatrixXd complement(dim_, dim_);
  for (int i = 0; i < dim_; ++i)
    for (int j = 0; j < dim_; ++j) complement(i, j) = (i == j) - projection[static_cast<std::size_t>(i * dim_ + j)];
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> R(rows.data(), dim_,
                                                                                                    n_motions);
  gram += R.transpose() * complement * R;
}

std::size_t RigidMotionGram::rank() const {
  if (components == 0) return 0;
  const int n = static_cast<int>(gram.rows());
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
  if (span > 0) scale.tail(n / 2).setConstant(1 / span);
  const Eigen::MatrixXd scaled = scale.asDiagonal() * gram * scale.asDiagonal();
  const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
  const double largest = eigenvalues.maxCoeff();
  return static_cast<std::size_t>((eigenvalues.array() > 1e-10 * largest).count());
}

}  // namespace snede
