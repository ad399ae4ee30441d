#include "mesh/edit_footprint.hpp"

namespace snede {

EditFootprint::EditFootprint(Connectivity& connectivity) : connectivity_(connectivity) {
  connectivity_.add_watcher(this);
}

EditFootprint::~EditFootprint() { connectivity_.remove_watcher(this); }

void EditFootprint::touch(VertexId v) {
  if (static_cast<std::size_t>(v) >= marked_.size()) marked_.resize(static_cast<std::size_t>(v) + 1, false);
  if (marked_[v]) return;
  marked_[v] = true;
  vertices_.push_back(v);
}

void EditFootprint::touch_all(const Simplex& cell) {
  for (VertexId v : cell.vertices()) touch(v);
}

void EditFootprint::on_change(const Connectivity& connectivity, const ConnectivityChange& change) {
  for (const auto& [e, simplex] : change.removed_elements) touch_all(simplex);
  for (ElementId e : change.added_elements) touch_all(connectivity.element(e).simplex);
  for (const auto& [e, before] : change.changed_elements) {
    touch_all(before);
    touch_all(connectivity.element(e).simplex);
  }
  for (ElementId e : change.reshaped_elements) touch_all(connectivity.element(e).simplex);
  for (const VertexEvent& event : change.vertex_events) touch(event.vertex);
}

}  // namespace snede
