#include "problem/piece_holding.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "mesh/piece_tracker.hpp"
#include "mesh/traversal.hpp"

namespace snede {
namespace {

}  // namespace

// The labels of the elements kept through the edits, and the vertices whose stars the edits
// changed since the last time they were settled.
class PieceHolding::EditWatcher final : public ConnectivityWatcher {
 public:
  explicit EditWatcher(Connectivity& connectivity) : connectivity_(connectivity), tracker_(connectivity) {
    connectivity_.add_watcher(this);
  }
  ~EditWatcher() override { connectivity_.remove_watcher(this); }
  EditWatcher(const EditWatcher&) = delete;
  EditWatcher& operator=(const EditWatcher&) = delete;

  void init(const Connectivity&) override {}
  void on_change(const Connectivity& c, const ConnectivityChange& change) override {
    ++changes_heard_;
    tracker_.on_change(c, change);
    for (const auto& [e, simplex] : change.removed_elements) touch_all(simplex);
    for (ElementId e : change.added_elements) touch_all(c.element(e).simplex);
    for (const auto& [e, before] : change.changed_elements) {
      touch_all(before);
      touch_all(c.element(e).simplex);
    }
    for (const VertexEvent& event : change.vertex_events) touch(event.vertex);
  }

  PieceTracker& tracker() { return tracker_; }
  // Starts the labels afresh, as connected_components numbers them.
  void relabel() {
    tracker_ = PieceTracker(connectivity_);
    settled();
  }
  std::span<const VertexId> touched() const { return touched_; }
  bool touched(VertexId v) const { return static_cast<std::size_t>(v) < marked_.size() && marked_[v]; }
  // Changes heard since attached: a question asked within a batch (whose change is heard at its
  // end) is not answered with labels that pretend to know it.
  std::uint64_t changes_heard() const { return changes_heard_; }
  void settled() {
    for (VertexId v : touched_) marked_[v] = false;
    touched_.clear();
  }

 private:
  void touch(VertexId v) {
    if (static_cast<std::size_t>(v) >= marked_.size()) marked_.resize(static_cast<std::size_t>(v) + 1, false);
    if (marked_[v]) return;
    marked_[v] = true;
    touched_.push_back(v);
  }
  void touch_all(const Simplex& cell) {
    for (VertexId v : cell.vertices()) touch(v);
  }

  Connectivity& connectivity_;
  PieceTracker tracker_;
  std::vector<VertexId> touched_;
  std::vector<bool> marked_;  // by vertex id: in touched_
  std::uint64_t changes_heard_ = 0;
};

PieceHolding::PieceHolding(const Mesh& mesh) : mesh_(mesh) {}

PieceHolding::PieceHolding(Mesh& mesh, FollowEdits) : mesh_(mesh), followed_(&mesh.connectivity()) {}

PieceHolding::~PieceHolding() = default;

template <class Label>
void PieceHolding::label_vertices(Label label, int pieces) {
  const Connectivity& c = mesh_.connectivity();
  pieces_ = pieces;
  vertex_piece_.assign(mesh_.n_points(), -1);
  hinge_pieces_.clear();
  piece_cells_.assign(pieces, 0);
  piece_first_cell_.assign(pieces, no_id);
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    const int piece = label(e);
    if (piece_cells_[piece]++ == 0) piece_first_cell_[piece] = e;
    for (VertexId v : c.element(e).simplex.vertices()) {
      if (vertex_piece_[v] < 0) vertex_piece_[v] = piece;
      else if (vertex_piece_[v] != piece) hinge_pieces_.emplace_back(v, piece);
    }
  }
  sort_hinges();
  labels_from_scratch_ = true;
  ++whole_labellings_;
}

void PieceHolding::sort_hinges() {
  std::sort(hinge_pieces_.begin(), hinge_pieces_.end());
  hinge_pieces_.erase(std::unique(hinge_pieces_.begin(), hinge_pieces_.end()), hinge_pieces_.end());
}

void PieceHolding::label_from_scratch() {
  const Connectivity& c = mesh_.connectivity();
  if (followed_) {
    // The watcher's tracker labels the elements as connected_components numbers them.
    if (watcher_) watcher_->relabel();
    else watcher_ = std::make_unique<EditWatcher>(*followed_);
    const PieceTracker& tracker = watcher_->tracker();
    label_vertices([&](ElementId e) { return tracker.label(e); }, tracker.pieces());
    labelled_changes_ = watcher_->changes_heard();
  } else {
    const auto [label, pieces] = connected_components(c);
    label_vertices([&](ElementId e) { return label[e]; }, pieces);
    labelled_revision_ = c.topology_revision();
  }
  labelled_ = true;
}

void PieceHolding::label_vertex(VertexId v) {
  const Connectivity& c = mesh_.connectivity();
  const PieceTracker& tracker = watcher_->tracker();
  vertex_piece_[v] = -1;
  const std::int32_t uses = c.n_vertex_uses(v);
  if (uses == 0) return;
  // The elements reached around v through faces are of one piece; where they are not all of
  // v's elements, v is where pieces (or parts of one) meet without a face: every element is
  // looked at (a scan, O(n), for such vertices only).
  std::vector<ElementId> star = vertex_star(c, v, c.vertex_element(v));
  if (static_cast<std::int32_t>(star.size()) != uses) star = vertex_star(c, v);
  std::sort(star.begin(), star.end());
  for (ElementId e : star) {
    const int piece = tracker.label(e);
    if (vertex_piece_[v] < 0) vertex_piece_[v] = piece;
    else if (vertex_piece_[v] != piece) hinge_pieces_.emplace_back(v, piece);
  }
}

void PieceHolding::follow_edits() {
  const Connectivity& c = mesh_.connectivity();
  labels_from_scratch_ = false;
  if (watcher_->tracker().update(c)) {
    // A piece split, or the labels could not follow locally (pieces joined): the tracker
    // labelled every element again.
    const PieceTracker& tracker = watcher_->tracker();
    label_vertices([&](ElementId e) { return tracker.label(e); }, tracker.pieces());
  } else {
    vertex_piece_.resize(mesh_.n_points(), -1);
    std::erase_if(hinge_pieces_, [&](const auto& hinge) { return watcher_->touched(hinge.first); });
    for (VertexId v : watcher_->touched())
      if (static_cast<std::size_t>(v) < vertex_piece_.size()) label_vertex(v);
    sort_hinges();
    pieces_ = watcher_->tracker().pieces();
  }
  watcher_->settled();
  labelled_changes_ = watcher_->changes_heard();
}

std::vector<RigidMotionGram> PieceHolding::grams(const Constraints& constraints) const {
  const int dim = constraints.dim();
  std::vector<RigidMotionGram> grams(pieces_, RigidMotionGram(dim));
  std::vector<double> block(static_cast<std::size_t>(dim * dim));
  const VertexId n = std::min(constraints.n_points(), static_cast<VertexId>(vertex_piece_.size()));
  auto add = [&](VertexId v, int piece) {
    const std::size_t components = constraints.constrained_components(v);
    if (components == 0) return;
    constraints.projection_block(v, block);
    grams[piece].add(mesh_.point(v), block, components);
  };
  for (VertexId v = 0; v < n; ++v)
    if (vertex_piece_[v] >= 0) add(v, vertex_piece_[v]);
  for (const auto& [v, piece] : hinge_pieces_)
    if (v < n) add(v, piece);
  return grams;
}

std::vector<LoosePiece> PieceHolding::loose_of(const std::vector<RigidMotionGram>& grams, bool by_count) const {
  const std::size_t n_motions = grams.empty() ? 0 : static_cast<std::size_t>(grams.front().gram.rows());
  std::vector<LoosePiece> loose;
  for (int piece = 0; piece < pieces_; ++piece) {
    const std::size_t stopped = grams[piece].rank();
    if ((by_count ? grams[piece].components : stopped) < n_motions)
      loose.push_back({piece, pieces_, piece_cells_[piece], piece_first_cell_[piece], grams[piece].components, stopped,
                       n_motions});
  }
  return loose;
}

std::vector<LoosePiece> PieceHolding::loose_pieces(const Constraints& constraints) {
  if (!labelled_) {
    label_from_scratch();
  } else if (followed_) {
    if (watcher_->changes_heard() != labelled_changes_) follow_edits();
  } else if (labelled_revision_ != mesh_.connectivity().topology_revision()) {
    label_from_scratch();
  }
  // A membrane has no bending stiffness: tension holds it, not the rank of its supports (a
  // sheet hung from a straight rod is a membrane scene), so it keeps the count.
  const bool by_count = mesh_.is_surface();
  std::vector<LoosePiece> loose = loose_of(grams(constraints), by_count);
  if (loose.empty() || labels_from_scratch_) return loose;
  // Labels kept through edits may leave a label that no piece has any more (a piece dissected
  // away), and number pieces by their history: a loose piece is reported as labelled now.
  label_from_scratch();
  return loose_of(grams(constraints), by_count);
}

void PieceHolding::require_held(const Constraints& constraints) {
  const std::vector<LoosePiece> loose = loose_pieces(constraints);
  if (loose.empty()) return;
  throw std::invalid_argument(
      not_held_message(loose, mesh_.connectivity().element(loose.front().first_cell).simplex.vertices()[0]));
}

std::string not_held_message(const std::vector<LoosePiece>& loose, std::int64_t vertex_of_first) {
  const LoosePiece& first = loose.front();
  const std::string which =
      first.pieces == 1 ? "it is one piece of " + std::to_string(first.cells) + " cells with "
                        : "piece " + std::to_string(first.piece + 1) + " of " + std::to_string(first.pieces) + " (" +
                              std::to_string(first.cells) + " cells, vertex " + std::to_string(vertex_of_first) +
                              " among them) has ";
  std::string message = "the body is not held: " + which + std::to_string(first.constrained_components) +
                        " constrained displacement components, which stop " +
                        std::to_string(first.rigid_motions_stopped) + " of its " +
                        std::to_string(first.rigid_motions) +
                        " rigid motions (3 in 2D, 6 in 3D: vertices on one line leave a solid free to turn " +
                        "about it; a membrane needs 6 constrained components)";
  if (first.pieces == 1) return message + "; fix some of its vertices with body.fix";
  message += "; " + std::to_string(loose.size()) + " of the " + std::to_string(first.pieces) + " pieces " +
             (loose.size() == 1 ? "is" : "are") + " not held. A static solve needs every piece held (a cut can " +
             "free one): fix some vertices of each with body.fix, or call body.fix_free_pieces() to fix each on " +
             "one of its cells where it is now (TetrahedralCutter(fix_free_pieces=True) does this while cutting)";
  return message;
}

}  // namespace snede
