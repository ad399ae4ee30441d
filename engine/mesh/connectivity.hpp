// The simplicial connectivity of §7.2–§7.3: Element objects (d-simplexes) and Face objects
// ((d-1)-simplexes) linked by `mate`, plus the boundary map. replace_elements and
// change_elements are the only code in snede that edits connectivity.
//
// Storage: elements and faces live in contiguous arrays addressed by 32-bit ids, with free
// lists so that ids stay stable while others are removed; the boundary is a hash map
// (the thesis's balanced trees cost O(log n) per lookup).
#pragma once

#include <algorithm>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "mesh/connectivity_watcher.hpp"
#include "mesh/simplex.hpp"

namespace snede {

struct Element {
  Simplex simplex;  // empty for a free slot
  std::array<FaceId, max_dimension + 1> faces{no_id, no_id, no_id, no_id};  // (7.1)
};

struct Face {
  Simplex simplex;
  ElementId element = no_id;  // no_id for a free slot; (7.2)
  FaceId mate = no_id;        // the face with the opposite orientation, if any; (7.3)
};

// A simultaneous vertex substitution π applied to one element (change_elements).
struct ElementSubstitution {
  ElementId element;
  std::vector<std::pair<VertexId, VertexId>> from_to;
  VertexId operator()(VertexId v) const {
    for (const auto& [from, to] : from_to)
      if (from == v) return to;
    return v;
  }
};

using BoundaryMap = std::unordered_map<Simplex, FaceId, SimplexHash>;

// The faces of the few elements one replace_elements call swaps, by simplex: a flat vector
// searched linearly, which at this size beats hashing and its allocations.
class LocalFaceMap {
 public:
  using Entry = std::pair<Simplex, FaceId>;
  using const_iterator = std::vector<Entry>::const_iterator;
  const_iterator begin() const { return entries_.begin(); }
  const_iterator end() const { return entries_.end(); }
  const_iterator find(const Simplex& sigma) const {
    return std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.first == sigma; });
  }
  bool count(const Simplex& sigma) const { return find(sigma) != end(); }
  // Adds σ → f unless σ is present; true if added.
  bool emplace(const Simplex& sigma, FaceId f) {
    if (count(sigma)) return false;
    entries_.emplace_back(sigma, f);
    return true;
  }
  // σ must be present.
  void assign(const Simplex& sigma, FaceId f) {
    for (Entry& e : entries_)
      if (e.first == sigma) e.second = f;
  }

 private:
  std::vector<Entry> entries_;
};

class Connectivity {
 public:
  explicit Connectivity(int dim);
  // Builds the connectivity of `n_cells` cells of dim+1 vertices each, every cell already
  // in positive orientation. Faces are matched by sorting (O(n log n), no hash map for the
  // interior). Throws std::invalid_argument naming the cells if a face is shared by more
  // than two cells, or by two cells on the same side, or if a cell is repeated.
  static Connectivity from_cells(int dim, std::span<const VertexId> cells);

  Connectivity(Connectivity&&) = default;
  Connectivity& operator=(Connectivity&&) = default;
  Connectivity(const Connectivity&) = delete;
  Connectivity& operator=(const Connectivity&) = delete;

  int dim() const { return dim_; }
  std::size_t n_elements() const { return n_elements_; }
  std::size_t n_faces() const { return faces_.size() - free_faces_.size(); }
  // Element ids are in [0, element_capacity()); some may be free slots.
  ElementId element_capacity() const { return static_cast<ElementId>(elements_.size()); }
  FaceId face_capacity() const { return static_cast<FaceId>(faces_.size()); }
  bool is_element(ElementId e) const;
  bool is_face(FaceId f) const;
  const Element& element(ElementId e) const { return elements_[e]; }
  const Face& face(FaceId f) const { return faces_[f]; }
  const BoundaryMap& boundary() const { return boundary_; }
  // The face of e not containing v (opposite-face), and the vertex of e not in f (opposite-vertex).
  FaceId opposite_face(ElementId e, VertexId v) const;
  VertexId opposite_vertex(ElementId e, FaceId f) const;
  // The neighbour of e across its j-th face, or no_id on the boundary.
  ElementId neighbor(ElementId e, int j) const;
  // Ids of all live elements, ascending.
  std::vector<ElementId> element_ids() const;

  // §7.3 replace-elements: removes `old_elements`, adds one element per simplex (each of
  // dimension d), reusing the Face objects of old faces that occur again and creating
  // matched pairs of new faces without passing them through the boundary map. Returns the
  // ids of the new elements, in the order of `new_simplexes`. Throws std::invalid_argument
  // (before changing anything) for a dead or repeated old element, a simplex of the wrong
  // dimension, or a face that would then be represented twice.
  std::vector<ElementId> replace_elements(std::span<const ElementId> old_elements,
                                          std::span<const Simplex> new_simplexes);
  // §7.3 change-elements: applies a vertex substitution per element, keeping every Element
  // and Face object (and id). Throws std::invalid_argument (before changing anything) for a
  // dead or repeated element or a substitution that is not injective on an element.
  void change_elements(std::span<const ElementSubstitution> substitutions);

  // Vertices: how many live elements contain v, and one of them (no_id if none). Kept
  // exact by replace_elements and change_elements (O(size of the change) per call).
  std::int32_t n_vertex_uses(VertexId v) const;
  ElementId vertex_element(VertexId v) const;

  // Vertex events (added, moved, removed) are recorded by the mesh and delivered with the
  // next change; notify_vertex_events() delivers them on their own (a move or removal
  // without element change). Moved vertices' stars become the change's reshaped_elements.
  void stage_vertex_event(VertexEvent event);
  void notify_vertex_events();

  void add_watcher(ConnectivityWatcher* watcher, WatchMode mode = WatchMode::merged);
  // The first watcher's reason to refuse a planned new cell (ConnectivityWatcher::refuses), or empty.
  std::string watcher_refusal(const Simplex& cell) const;
  void remove_watcher(ConnectivityWatcher* watcher);

  // Batches (nestable; see ChangeBatch): merged watchers hear of the operations in a batch
  // once, at its end.
  void begin_batch();
  void end_batch();
  bool in_batch() const { return batch_depth_ > 0; }

  // Increases with every operation: a cheap "has it changed" test.
  std::uint64_t revision() const { return revision_; }
  // Increases with every operation that adds, removes or changes an element or adds or removes
  // a vertex: what sparsities and piece labels depend on. A vertex moved in the reference
  // configuration (a cut's snap) changes revision() only.
  std::uint64_t topology_revision() const { return topology_revision_; }

  // Bytes held by the element, face and boundary containers (capacity, not just size).
  std::size_t memory_bytes() const;

 private:
  ElementId allocate_element(const Simplex& simplex);
  FaceId allocate_face(const Simplex& simplex);
  void release_element(ElementId e);
  void release_face(FaceId f);
  void link(FaceId a, FaceId b);
  // Links each unmatched face to its opposite, looked up among `local` faces first and then
  // in the boundary; the rest, and orphans left without a mate, join the boundary.
  template <class FaceMap>  // BoundaryMap or LocalFaceMap
  void pair_faces(std::span<const FaceId> unmatched, const FaceMap& local, std::span<const FaceId> orphans,
                  ConnectivityChange& change);
  // True if a face with simplex σ exists outside the elements being replaced.
  bool already_kept(const Simplex& sigma, const LocalFaceMap& old_faces,
                    const std::unordered_set<ElementId>& old_set) const;
  // Completes `change` (staged vertex events, reshaped elements), updates the vertex
  // incidences and tells the watchers (or merges it into the open batch).
  void notify(ConnectivityChange& change, std::span<const FaceId> orphans);
  void update_vertex_incidence(const ConnectivityChange& change, std::span<const FaceId> orphans);
  void ensure_vertex_capacity(VertexId v);
  void merge_into_batch(const ConnectivityChange& change);
  ConnectivityChange take_batch();

  int dim_;
  std::size_t n_elements_ = 0;
  std::vector<Element> elements_;
  std::vector<ElementId> free_elements_;
  std::vector<Face> faces_;
  std::vector<FaceId> free_faces_;
  BoundaryMap boundary_;
  std::vector<std::int32_t> vertex_uses_;      // by vertex id
  std::vector<ElementId> vertex_element_;      // by vertex id
  std::vector<VertexEvent> staged_vertex_events_;
  std::vector<std::pair<ConnectivityWatcher*, WatchMode>> watchers_;
  std::uint64_t revision_ = 0;
  std::uint64_t topology_revision_ = 0;

  // The open batch: what merged watchers will hear at its end.
  int batch_depth_ = 0;
  ConnectivityChange batch_;
  std::unordered_set<ElementId> batch_added_;                     // added during the batch, still live
  std::unordered_map<ElementId, std::size_t> batch_changed_;     // index into batch_.changed_elements
};

// Groups operations into one change for merged watchers: { ChangeBatch batch(c); ...edits... }.
// The merged change is delivered when the outermost batch ends (at destruction).
class ChangeBatch {
 public:
  explicit ChangeBatch(Connectivity& c) : c_(c) { c_.begin_batch(); }
  ~ChangeBatch() noexcept(false);
  ChangeBatch(const ChangeBatch&) = delete;
  ChangeBatch& operator=(const ChangeBatch&) = delete;

 private:
  Connectivity& c_;
};

}  // namespace snede
