// Small pieces shared by the coarse spaces of aggregation_multigrid and grid_multigrid.
#pragma once

#include <cstdint>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/traversal.hpp"

namespace snede {

// Union-find with path halving; the root of a set is its smallest member.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  std::int32_t find(std::int32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  // Joins the sets of a and b; returns the root of the union.
  std::int32_t unite(std::int32_t a, std::int32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return a;
    if (b < a) std::swap(a, b);
    parent_[b] = a;
    return a;
  }

 private:
  std::vector<std::int32_t> parent_;
};

// Orthonormalises the columns of `block` (rows × m, column-major) in order, dropping those
// that depend on earlier ones (Gram-Schmidt, twice for stability; a column whose norm falls
// below 1e-8 of its own is dependent). Returns the orthonormal columns Q (rows × k,
// column-major) and sets R = Qᵀ block (k × m, row-major).
std::vector<double> orthonormal_columns(const std::vector<double>& block, std::size_t rows, int m,
                                        std::vector<double>& R);
// The same Q without R, into `Q` (its storage reused: the grid levels call this per node copy);
// returns the number of columns kept.
std::size_t orthonormalise_columns(std::span<const double> block, std::size_t rows, int m, std::vector<double>& Q);

// The mean length of the cells' edges in the reference configuration (an edge shared by
// several cells counts once per cell); 0 for a mesh without cells.
double mean_edge_length(const Mesh& mesh);

// The mesh's vertex spacing, (measure of its cells / number of their vertices)^(1 / cell_dim)
// in the reference configuration, from the cells of `stars` (the mesh's cells): the edge of a cube (square) per vertex. On a graded mesh
// (refined along a needle's shaft) it follows where the volume is, while the mean edge length
// follows where the edges are; a coarse grid sized by it has about as many nodes per fine
// vertex on any mesh. 0 for a mesh without cells.
double vertex_spacing(const Mesh& mesh, const VertexStars& stars);

}  // namespace snede
