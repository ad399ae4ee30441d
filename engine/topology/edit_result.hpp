// The outcome of a local mesh edit (flip, split, insertion, collapse, removal, snap): done, or
// refused with the reason, in which case the mesh is exactly as it was (DESIGN: an edit that
// cannot be done cleanly is refused, never forced).
#pragma once

#include <string>

#include "mesh/simplex.hpp"

namespace snede {

struct EditResult {
  bool done = false;
  std::string reason;          // why it was refused; empty when done
  VertexId vertex = -1;        // the vertex an insertion or split created, if any

  static EditResult refused(std::string why) { return {false, std::move(why), -1}; }
  static EditResult success(VertexId created = -1) { return {true, {}, created}; }
};

}  // namespace snede
