// The footprint of the edits made to a connectivity since a moment: every vertex whose star an
// edit changed (a corner of a removed, added, changed or reshaped element, or an added, moved or
// removed vertex). What a structure built for the mesh of that moment must update, and nothing
// else (issue 49's change lists): outside the footprint every vertex has the same elements around
// it, with the same shapes, as then.
#pragma once

#include <span>
#include <vector>

#include "mesh/connectivity.hpp"

namespace snede {

class EditFootprint final : public ConnectivityWatcher {
 public:
  // Records the edits of `connectivity` from now until destruction (merged per batch).
  explicit EditFootprint(Connectivity& connectivity);
  ~EditFootprint() override;
  EditFootprint(const EditFootprint&) = delete;
  EditFootprint& operator=(const EditFootprint&) = delete;

  // The vertices edits touched since construction, each once, in the order first touched.
  std::span<const VertexId> vertices() const { return vertices_; }

  void init(const Connectivity&) override {}
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;

 private:
  void touch(VertexId v);
  void touch_all(const Simplex& cell);

  Connectivity& connectivity_;
  std::vector<VertexId> vertices_;
  std::vector<bool> marked_;  // by vertex id: in vertices_
};

}  // namespace snede
