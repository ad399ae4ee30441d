// The patches a smoothed formulation averages strains over (fem/formulation.hpp; Liu et al.'s
// smoothed FEM): each simplex gives an equal share of its measure to each of its edges
// (1/6 of a tetrahedron, 1/3 of a triangle) and to each of its vertices (1/(D+1)). A patch's
// strain is the share-weighted mean of its simplices' constant gradients, and its energy is
// its measure times W at that strain, so the total measure is the body's.
//
// Built from the element stream's live elements in O(n) (vertex by vertex, as
// mesh/traversal.hpp's stars), and rebuilt after a connectivity change: a cut duplicates the
// vertices of its lips, so their patches come apart with them.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fem/element_stream.hpp"

namespace snede {

template <int D>
class StrainPatches {
 public:
  static constexpr int edges_per_element = D * (D + 1) / 2;
  static constexpr double edge_share = 1.0 / edges_per_element;
  static constexpr double vertex_share = 1.0 / (D + 1);
  // The corners of each local edge.
  static constexpr std::array<std::array<int, 2>, edges_per_element> local_edges() {
    if constexpr (D == 3)
      return {{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
    else
      return {{{0, 1}, {0, 2}, {1, 2}}};
  }

  void build(const ElementStream<D>& stream, VertexId n_points);

  // Changes with every build: what was computed for one build is stale for the next.
  std::uint64_t generation() const { return generation_; }
  std::size_t n_edges() const { return edge_measure_.size(); }
  std::size_t n_vertices() const { return vertex_measure_.size(); }
  // Edge patch ids of element e's local edges (a free slot: −1).
  const std::array<std::int32_t, edges_per_element>& element_edges(ElementId e) const { return element_edges_[e]; }
  std::span<const double> edge_measure() const { return edge_measure_; }
  // Per vertex id (0 for a vertex no element uses).
  std::span<const double> vertex_measure() const { return vertex_measure_; }
  // The elements of edge patch k, and of vertex v's patch (its star).
  std::span<const ElementId> edge_elements(std::size_t k) const {
    return {edge_element_list_.data() + edge_start_[k], edge_start_[k + 1] - edge_start_[k]};
  }
  std::span<const ElementId> vertex_elements(VertexId v) const {
    return {vertex_element_list_.data() + vertex_start_[v], vertex_start_[v + 1] - vertex_start_[v]};
  }

 private:
  std::vector<std::array<std::int32_t, edges_per_element>> element_edges_;
  std::vector<double> edge_measure_, vertex_measure_;
  std::vector<std::size_t> edge_start_, vertex_start_;
  std::vector<ElementId> edge_element_list_, vertex_element_list_;
  std::uint64_t generation_ = 0;
};

}  // namespace snede
