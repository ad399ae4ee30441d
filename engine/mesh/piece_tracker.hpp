// The pieces of a mesh (elements joined through faces, §3.3) kept up to date across local
// edits at a cost that does not grow with the mesh.
//
// Every element carries a piece label. A change can only split a piece where the mesh
// changed: each part of a split piece contains an element that was added, changed, or
// given a new boundary face (otherwise the faces through which it was joined to the rest
// would still be there). So after a change the tracker searches breadth-first from those
// elements, one search per element, in lockstep, merging searches that meet. Searches
// from one piece that all meet leave it whole, usually within a few layers around the
// edit; a search that runs out of elements before meeting the others has found a part
// cut off. Only then, when a piece did split, are all elements relabelled (O(n)).
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/connectivity.hpp"
#include "mesh/connectivity_watcher.hpp"

namespace snede {

class PieceTracker {
 public:
  // Labels the elements of `c` (O(n)).
  explicit PieceTracker(const Connectivity& c);

  // To be called with every change of the connectivity: labels the added elements from
  // their neighbours and remembers where the mesh changed.
  void on_change(const Connectivity& c, const ConnectivityChange& change);

  // Settles the changes seen since the last call: true when a piece split (or labels had to
  // be rebuilt) and every element was relabelled, false when the pieces are as they were.
  bool update(const Connectivity& c);

  int pieces() const { return pieces_; }
  // Label in [0, pieces()) of a live element; valid after update().
  int label(ElementId e) const { return label_[e]; }
  // Elements visited by the last update's local search (what the update cost).
  std::size_t last_search_size() const { return last_search_size_; }

 private:
  void relabel(const Connectivity& c);
  // Whether the searches from `seeds` (all of one piece) find it split.
  bool splits(const Connectivity& c, const std::vector<ElementId>& seeds);

  std::vector<int> label_;             // per element id; -1 for a free slot or not yet known
  int pieces_ = 0;
  bool stale_ = false;                 // an added element could not be labelled locally
  std::vector<ElementId> changed_;     // where the mesh changed since the last update
  std::vector<std::uint32_t> stamp_;   // per element id: search epoch that visited it
  std::vector<int> owner_;             // per element id: the search that visited it
  std::uint32_t epoch_ = 0;
  std::size_t last_search_size_ = 0;
};

}  // namespace snede
