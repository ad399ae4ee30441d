// The per-element data the element loops stream through (§2.3; §7.4 for how it follows the
// mesh): each element's oriented vertices (int32) and reference data Z⁻¹, |τ|, in element-id
// order, in blocks of batch_width elements. Inside a block each quantity is stored entry by
// entry with the block's elements side by side, so one entry of batch_width elements is one
// Batch: a loop reads memory once, front to back, and loads Z⁻¹ and |τ| with aligned vector
// loads (96 bytes per tetrahedron, no pointer chasing through Element records). A vertex v is
// stored as D·v, where its row starts in a (n_points, D) nodal array, so that a gather or
// scatter is one load of the index and one of the values (storing v cost two more
// instructions per node and lane, ~20% of the linear tangent's); int32 then holds vertex ids
// below 2³¹/D (715 million in 3D).
//
// Element e lives in block e / batch_width, lane e % batch_width: no id → slot map. The
// owner keeps it in step with the watcher's changes, O(1) per element changed. A removed
// element leaves a free slot rather than being compacted away: the connectivity's free list
// hands its id to the next element added, so slots refill, the capacity never exceeds the
// largest element count the mesh had, and the id order (the mesh's locality) is kept, where
// compaction would need a map on every access and would scatter the order. A free slot has
// rows all 0 (a live element's vertices are distinct), Z⁻¹ = I and |τ| = 0: evaluating it is
// harmless (F = I), and the loops leave it out of sums and reports.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "fem/batch.hpp"
#include "fem/element_kernel.hpp"
#include "fem/nodal_lanes.hpp"
#include "mesh/connectivity_watcher.hpp"

namespace snede {

template <int D>
struct ElementBlock {
  ElementReference<D, Batch> reference;
  std::array<std::array<std::int32_t, batch_width>, D + 1> rows;  // D·vertex, [corner][lane], positively oriented
};

template <int D>
class ElementStream {
 public:
  using Vertices = std::array<VertexId, D + 1>;

  // Makes room for element ids [0, capacity); new slots are free. Never shrinks.
  void reserve_ids(ElementId capacity);
  void store(ElementId e, const Vertices& vertices, const ElementReference<D>& reference);
  void release(ElementId e);

  const std::vector<ElementBlock<D>>& blocks() const { return blocks_; }
  ElementId capacity() const { return static_cast<ElementId>(blocks_.size() * batch_width); }
  bool is_live(ElementId e) const { return live_lanes(block_of(e)) >> (e % batch_width) & 1; }
  Vertices vertices(ElementId e) const;
  ElementReference<D> reference(ElementId e) const;

  // The lanes of `block` that hold live elements (those whose first two rows differ).
  static LaneMask live_lanes(const ElementBlock<D>& block) {
    LaneIndices first, second;
    std::memcpy(&first, block.rows[0].data(), sizeof first);
    std::memcpy(&second, block.rows[1].data(), sizeof second);
    return true_lanes(first != second);
  }

 private:
  const ElementBlock<D>& block_of(ElementId e) const { return blocks_[e / batch_width]; }
  ElementBlock<D>& block_of(ElementId e) { return blocks_[e / batch_width]; }

  std::vector<ElementBlock<D>> blocks_;
};

// How many blocks ahead the loops ask for the next blocks' data. The hardware prefetcher
// alone keeps too few of these sequential misses in flight once a block's gathers fill the
// reorder window: at 10⁶ tetrahedra a block loop ran 3× slower than its data's bandwidth
// allows; 8 blocks (32 elements, ~3 KB) ahead brings it back (measured 4–32: all alike).
inline constexpr std::size_t prefetch_distance = 8;

// Asks for block b + prefetch_distance of `blocks` (if there is one), every cache line of it.
template <int D>
void prefetch_ahead(std::span<const ElementBlock<D>> blocks, std::size_t b) {
  if (b + prefetch_distance >= blocks.size()) return;
  const char* start = reinterpret_cast<const char*>(&blocks[b + prefetch_distance]);
  for (std::size_t offset = 0; offset < sizeof(ElementBlock<D>); offset += 64) __builtin_prefetch(start + offset);
}

// U (D×D) of every lane: column j − 1 holds x_j − x_0 of the element's nodes' values in
// `nodal` ((n_points, D) row-major).
template <int D>
Tensor<Batch, D> gather_differences(std::span<const double> nodal, const ElementBlock<D>& block) {
  const std::array<Batch, D> x0 = load_nodes<D>(nodal.data(), block.rows[0].data());
  Tensor<Batch, D> U;
  for (int j = 1; j <= D; ++j) {
    const std::array<Batch, D> xj = load_nodes<D>(nodal.data(), block.rows[j].data());
    for (int k = 0; k < D; ++k) U(k, j - 1) = xj[k] - x0[k];
  }
  return U;
}

// Adds the columns G to nodes 1..D and minus their sum to node 0, for the lanes in `lanes`,
// lane after lane (elements sharing a node add in element order).
template <int D>
void scatter_columns(std::span<double> out, const ElementBlock<D>& block, const Tensor<Batch, D>& G, LaneMask lanes) {
  std::array<Batch, D> node0;
  for (int k = 0; k < D; ++k) {
    Batch sum = G(k, 0);
    for (int j = 2; j <= D; ++j) sum += G(k, j - 1);
    node0[k] = -sum;
  }
  add_to_nodes<D>(out.data(), block.rows[0].data(), node0, lanes);
  for (int j = 1; j <= D; ++j) {
    std::array<Batch, D> column;
    for (int k = 0; k < D; ++k) column[k] = G(k, j - 1);
    add_to_nodes<D>(out.data(), block.rows[j].data(), column, lanes);
  }
}

}  // namespace snede
