// Watchers (§7.4): the rest of the engine learns of every connectivity change through them.
// Changes are reported once per operation, as one batch, so a watcher can reissue sizes once.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "mesh/simplex.hpp"

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
};

class ConnectivityWatcher {
 public:
  virtual ~ConnectivityWatcher() = default;
  // Called once when the watcher is attached, with the connectivity as it is then.
  virtual void init(const Connectivity& connectivity) = 0;
  // Called after every replace_elements / change_elements, when the connectivity is valid again.
  virtual void on_change(const Connectivity& connectivity, const ConnectivityChange& change) = 0;
};

}  // namespace snede
