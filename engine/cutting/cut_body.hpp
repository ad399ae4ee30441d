// What a cutter asks of the simulation running on the mesh it cuts. The cutters sit below the
// solvers: they see the body only through these calls, which a caller with a model fills
// (bindings/cut_model_adapter, where the two layers meet) and a bare mesh leaves empty (cut as it is, no supports).
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "core/exclusive_use.hpp"
#include "mesh/connectivity_watcher.hpp"

namespace snede {

// One read of the body's displacement u: mesh.dim() numbers per mesh point row, valid while
// this lives (`hold` keeps the simulation's storage open for it, if it needs to).
struct DisplacementRead {
  std::span<const double> values;
  std::shared_ptr<const void> hold;
};

// u as it is now; unset for a bare mesh (then the deformed configuration is the reference).
using DisplacementSource = std::function<DisplacementRead()>;

struct CutBody {
  DisplacementSource displacement;
  // Whether vertex v is a support: snapping leaves it where the user put it (§3.2.2).
  std::function<bool(VertexId)> is_support;
  // After a cut that separated pieces: one cell of each piece the supports no longer hold.
  std::function<std::vector<ElementId>()> free_pieces;
  // What becomes of such a piece (§3.3: fixed where it is, so that the next static solve is
  // well posed), given one of its faces' vertices.
  std::function<void(std::span<const VertexId> face)> hold_free_piece;
  // The body's owner, claimed by each cut (one thread at a time); null for a bare mesh.
  ExclusiveUse* exclusive_use = nullptr;
};

}  // namespace snede
