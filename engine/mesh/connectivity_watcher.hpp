// Watchers (§7.4): the rest of the engine learns of every mesh change through them. A change
// lists element changes and, in order, the vertices added, moved or removed with them. A
// watcher receives one change per operation, or — for a batch of operations (ChangeBatch,
// e.g. one refine_around) — one merged change at its end, so it reissues sizes once.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "mesh/simplex.hpp"
#include "mesh/vertex_parents.hpp"

namespace snede {

using ElementId = std::int32_t;
using FaceId = std::int32_t;
inline constexpr std::int32_t no_id = -1;

class Connectivity;

struct ConnectivityChange {
  // Elements that no longer exist, with the simplex they had (their ids may be reused
  // by added_elements of the same change).
  std::vector<std::pair<ElementId, Simplex>> removed_elements;
  std::vector<ElementId> added_elements;
  // change_elements: same object, new simplex; paired with the simplex it had before.
  std::vector<std::pair<ElementId, Simplex>> changed_elements;
  // Boundary simplexes that left the boundary map, and faces that entered it.
  std::vector<Simplex> boundary_removed;
  std::vector<FaceId> boundary_added;
  // Vertices added, moved (in the reference configuration) or removed, in order.
  std::vector<VertexEvent> vertex_events;
  // Live elements, not among added or changed ones, whose corners moved: their reference
  // data (Z⁻¹, volume) must be recomputed.
  std::vector<ElementId> reshaped_elements;

  bool empty() const {
    return removed_elements.empty() && added_elements.empty() && changed_elements.empty() &&
           boundary_removed.empty() && boundary_added.empty() && vertex_events.empty();
  }
};

// How a watcher wants to hear of changes made inside a ChangeBatch: merged once at its end
// (sizes, reference data), or after each operation (the bisection hierarchy, which follows
// every split).
enum class WatchMode : std::uint8_t { merged, each_operation };

class ConnectivityWatcher {
 public:
  virtual ~ConnectivityWatcher() = default;
  // Called once when the watcher is attached, with the connectivity as it is then.
  virtual void init(const Connectivity& connectivity) = 0;
  // Called after every operation (replace_elements, change_elements, a vertex move or
  // removal), or once per batch, when the mesh is valid again.
  virtual void on_change(const Connectivity& connectivity, const ConnectivityChange& change) = 0;
  // Why a cell an edit plans to add would break this watcher's fields (a body: inverted in its
  // deformed configuration), or empty. Edits that choose among several retriangulations ask
  // before they commit to one (remove_vertex_by_flips), so they choose one every field admits.
  virtual std::string refuses(const Simplex& /*cell*/) const { return {}; }
};

}  // namespace snede
