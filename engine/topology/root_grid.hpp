// A uniform grid over the bounding boxes of the bisection hierarchy's roots (§6.5), so that
// point location — refine_around's first step — tests the few roots near the point instead of
// every root of the mesh (a scan cost 6 ms at 10⁵ tetrahedra, 60 ms at 10⁶, per call), and
// refinement along a needle's shaft the roots near the shaft. Built in
// O(roots); roots added afterwards are listed apart and tested at every query, until there are
// a quarter as many of them as of the grid's roots and the owner rebuilds it.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "mesh/simplex.hpp"

namespace snede {

using NodeId = std::int32_t;

struct BoundingBox {
  std::array<double, max_dimension> lo{}, hi{};
};

class RootGrid {
 public:
  bool built() const { return built_; }
  // Forgets the grid: the owner rebuilds it before the next query.
  void clear();
  // Cells about twice the roots' mean box size per axis, at most two cells per root.
  void build(int dim, std::span<const NodeId> roots, const std::function<BoundingBox(NodeId)>& box_of);
  // A root made after build(): a candidate of every query.
  void add(NodeId root) { added_.push_back(root); }
  std::size_t n_built() const { return n_built_; }
  std::size_t n_added() const { return added_.size(); }
  // Every root whose box contains x is among these (each once): those whose box meets x's cell,
  // then the roots added since build(). x: (dim,).
  std::vector<NodeId> candidates(std::span<const double> x) const;
  // Every root whose box meets `box` is among these, each once, in increasing order (the grid's
  // roots in the cells the box meets, and the roots added since build()).
  std::vector<NodeId> candidates(const BoundingBox& box) const;

 private:
  // The cell index along axis k of coordinate c, clamped to the grid.
  int cell_along(int k, double c) const;
  // visit(cell) for every cell `box` meets.
  template <class Visit>
  void for_each_cell(const BoundingBox& box, Visit visit) const;

  bool built_ = false;
  int dim_ = 0;
  std::size_t n_built_ = 0;
  std::array<double, max_dimension> lo_{}, cell_width_{};
  std::array<int, max_dimension> n_cells_{};
  std::vector<std::size_t> cell_start_;  // CSR: the roots of cell c are roots_[cell_start_[c] .. cell_start_[c + 1])
  std::vector<NodeId> roots_;
  std::vector<NodeId> added_;
};

}  // namespace snede
