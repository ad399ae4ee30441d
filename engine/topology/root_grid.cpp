#include "topology/root_grid.hpp"

#include <algorithm>
#include <cmath>

namespace snede {

void RootGrid::clear() {
  built_ = false;
  n_built_ = 0;
  cell_start_.clear();
  roots_.clear();
  added_.clear();
}

int RootGrid::cell_along(int k, double c) const {
  const double cell = std::floor((c - lo_[k]) / cell_width_[k]);
  return static_cast<int>(std::clamp(cell, 0.0, static_cast<double>(n_cells_[k] - 1)));
}

template <class Visit>
void RootGrid::for_each_cell(const BoundingBox& box, Visit visit) const {
  std::array<int, max_dimension> first{}, last{}, index{};
  for (int k = 0; k < dim_; ++k) {
    first[k] = index[k] = cell_along(k, box.lo[k]);
    last[k] = cell_along(k, box.hi[k]);
  }
  for (;;) {
    std::size_t cell = 0;
    for (int k = 0; k < dim_; ++k) cell = cell * static_cast<std::size_t>(n_cells_[k]) + static_cast<std::size_t>(index[k]);
    visit(cell);
    int k = dim_ - 1;
    while (k >= 0 && index[k] == last[k]) index[k] = first[k], --k;
    if (k < 0) return;
    ++index[k];
  }
}

void RootGrid::build(int dim, std::span<const NodeId> roots, const std::function<BoundingBox(NodeId)>& box_of) {
  clear();
  dim_ = dim;
  std::vector<BoundingBox> boxes;
  boxes.reserve(roots.size());
  BoundingBox all;
  all.lo.fill(HUGE_VAL);
  all.hi.fill(-HUGE_VAL);
  std::array<double, max_dimension> mean_size{};
  for (NodeId r : roots) {
    const BoundingBox& box = boxes.emplace_back(box_of(r));
    for (int k = 0; k < dim; ++k) {
      all.lo[k] = std::min(all.lo[k], box.lo[k]);
      all.hi[k] = std::max(all.hi[k], box.hi[k]);
      mean_size[k] += (box.hi[k] - box.lo[k]) / static_cast<double>(roots.size());
    }
  }
  std::size_t n_total = 1;
  for (int k = 0; k < dim; ++k) {
    const double extent = roots.empty() ? 0.0 : all.hi[k] - all.lo[k];
    n_cells_[k] = extent > 0 && mean_size[k] > 0 ? static_cast<int>(std::ceil(extent / (2 * mean_size[k]))) : 1;
    n_total *= static_cast<std::size_t>(n_cells_[k]);
  }
  // At most two cells per root: coarsen every axis alike (a flat or very graded mesh).
  const double coarsening = std::pow(static_cast<double>(n_total) / std::max<double>(2.0 * roots.size(), 1.0), 1.0 / dim);
  n_total = 1;
  for (int k = 0; k < dim; ++k) {
    if (coarsening > 1) n_cells_[k] = std::max(1, static_cast<int>(n_cells_[k] / coarsening));
    lo_[k] = roots.empty() ? 0.0 : all.lo[k];
    const double extent = roots.empty() ? 0.0 : all.hi[k] - all.lo[k];
    cell_width_[k] = extent > 0 ? extent / n_cells_[k] : 1.0;
    n_total *= static_cast<std::size_t>(n_cells_[k]);
  }
  // Counting sort of (cell, root) pairs into the CSR arrays: count, then place.
  cell_start_.assign(n_total + 1, 0);
  for (const BoundingBox& box : boxes) for_each_cell(box, [&](std::size_t cell) { ++cell_start_[cell + 1]; });
  for (std::size_t c = 0; c < n_total; ++c) cell_start_[c + 1] += cell_start_[c];
  roots_.resize(cell_start_[n_total]);
  std::vector<std::size_t> next(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < roots.size(); ++i)
    for_each_cell(boxes[i], [&](std::size_t cell) { roots_[next[cell]++] = roots[i]; });
  n_built_ = roots.size();
  built_ = true;
}

std::vector<NodeId> RootGrid::candidates(std::span<const double> x) const {
  std::size_t cell = 0;
  for (int k = 0; k < dim_; ++k) cell = cell * static_cast<std::size_t>(n_cells_[k]) + static_cast<std::size_t>(cell_along(k, x[k]));
  std::vector<NodeId> found(roots_.begin() + static_cast<std::ptrdiff_t>(cell_start_[cell]),
                            roots_.begin() + static_cast<std::ptrdiff_t>(cell_start_[cell + 1]));
  found.insert(found.end(), added_.begin(), added_.end());
  return found;
}

std::vector<NodeId> RootGrid::candidates(const BoundingBox& box) const {
  std::vector<NodeId> found;
  for_each_cell(box, [&](std::size_t cell) {
    found.insert(found.end(), roots_.begin() + static_cast<std::ptrdiff_t>(cell_start_[cell]),
                 roots_.begin() + static_cast<std::ptrdiff_t>(cell_start_[cell + 1]));
  });
  found.insert(found.end(), added_.begin(), added_.end());
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

}  // namespace snede
