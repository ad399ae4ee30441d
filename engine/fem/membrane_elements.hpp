// The per-element data of a membrane (a surface mesh in 3D): each triangle's oriented
// vertices and MembraneReference, in element-id order, a slot per id as in ElementStream
// (a removed element's slot is freed and refilled when the connectivity reuses its id).
// One element at a time, not in SIMD blocks: surfaces are small next to volume meshes.
#pragma once

#include <array>
#include <vector>

#include "fem/membrane_kernel.hpp"
#include "mesh/connectivity_watcher.hpp"

namespace snede {

class MembraneElements {
 public:
  using Vertices = std::array<VertexId, 3>;

  // Makes room for element ids [0, capacity); new slots are free. Never shrinks.
  void reserve_ids(ElementId capacity) {
    if (static_cast<std::size_t>(capacity) > slots_.size()) slots_.resize(capacity);
  }
  void store(ElementId e, const Vertices& vertices, const MembraneReference& reference) {
    slots_[e] = {vertices, reference, true};
  }
  void release(ElementId e) { slots_[e] = {}; }

  bool is_live(ElementId e) const { return slots_[e].live; }
  const Vertices& vertices(ElementId e) const { return slots_[e].vertices; }
  const MembraneReference& reference(ElementId e) const { return slots_[e].reference; }

  // Calls visit(e, vertices, reference) for every live element, in id order.
  template <class Visit>
  void for_each_live(Visit&& visit) const {
    for (std::size_t e = 0; e < slots_.size(); ++e)
      if (slots_[e].live) visit(static_cast<ElementId>(e), slots_[e].vertices, slots_[e].reference);
  }

 private:
  struct Slot {
    Vertices vertices{};
    MembraneReference reference;
    bool live = false;
  };
  std::vector<Slot> slots_;
};

}  // namespace snede
