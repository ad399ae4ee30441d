#include "mesh/connectivity.hpp"

#include <algorithm>
#include <exception>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include "mesh/traversal.hpp"

namespace snede {
namespace {

std::string element_text(ElementId e) { return "element " + std::to_string(e); }

}  // namespace

Connectivity::Connectivity(int dim) : dim_(dim) {
  if (dim < 1 || dim > max_dimension)
    throw std::invalid_argument("Connectivity: dimension must be 1.." + std::to_string(max_dimension) +
                                ", got " + std::to_string(dim));
}

Connectivity Connectivity::from_cells(int dim, std::span<const VertexId> cells) {
  Connectivity c(dim);
  const int n_vertices_per_cell = dim + 1;
  if (cells.size() % n_vertices_per_cell != 0)
    throw std::invalid_argument("Connectivity::from_cells: cell array length is not a multiple of " +
                                std::to_string(n_vertices_per_cell));
  const std::size_t n_cells = cells.size() / n_vertices_per_cell;
  c.elements_.resize(n_cells);
  c.faces_.resize(n_cells * n_vertices_per_cell);
  c.n_elements_ = n_cells;

  // The faces sorted by their vertices bring the two sides of each interior face together: a
  // counting sort by the first (smallest) vertex, then each vertex's few faces by the rest. Only
  // face ids move (4 bytes a face): building a large mesh's connectivity peaks at what it keeps
  // plus little more (issue 52).
  VertexId n_vertices = 0;
  for (VertexId v : cells) n_vertices = std::max(n_vertices, v + 1);
  std::vector<FaceId> first(static_cast<std::size_t>(n_vertices) + 1, 0);  // each vertex's bucket start
  for (std::size_t e = 0; e < n_cells; ++e) {
    Element& element = c.elements_[e];
    element.simplex = Simplex(1, cells.subspan(e * n_vertices_per_cell, n_vertices_per_cell));
    for (int j = 0; j < n_vertices_per_cell; ++j) {
      const FaceId f = static_cast<FaceId>(e * n_vertices_per_cell + j);
      Face& face = c.faces_[f];
      face.simplex = element.simplex.subn(j);
      face.element = static_cast<ElementId>(e);
      element.faces[j] = f;
      ++first[static_cast<std::size_t>(face.simplex.vertex(0)) + 1];
    }
  }
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<FaceId> keys(c.faces_.size());
  for (FaceId f = 0; f < static_cast<FaceId>(keys.size()); ++f)
    keys[static_cast<std::size_t>(first[static_cast<std::size_t>(c.faces_[f].simplex.vertex(0))]++)] = f;
  // `first` now holds each bucket's end, which is the next one's start.
  const auto by_vertices = [&](FaceId a, FaceId b) {
    const auto va = c.faces_[a].simplex.vertices(), vb = c.faces_[b].simplex.vertices();
    return std::lexicographical_compare(va.begin(), va.end(), vb.begin(), vb.end());
  };
  for (std::size_t v = 0, begin = 0; v < static_cast<std::size_t>(n_vertices); begin = first[v++])
    std::sort(keys.begin() + static_cast<std::ptrdiff_t>(begin), keys.begin() + first[v], by_vertices);
  std::vector<FaceId>().swap(first);
  const auto same_vertices = [&](FaceId a, FaceId b) { return c.faces_[a].simplex.same_vertices(c.faces_[b].simplex); };

  for (std::size_t i = 0; i < keys.size();) {
    std::size_t end = i + 1;
    while (end < keys.size() && same_vertices(keys[end], keys[i])) ++end;
    const FaceId a = keys[i];
    if (end - i == 1) {
      c.boundary_.emplace(c.faces_[a].simplex, a);
    } else {
      const FaceId b = keys[i + 1];
      const ElementId ea = c.faces_[a].element, eb = c.faces_[b].element;
      for (std::size_t p = i; p < end; ++p)  // a repeated cell is named as such, first
        for (std::size_t q = p + 1; q < end; ++q) {
          const ElementId ep = c.faces_[keys[p]].element, eq = c.faces_[keys[q]].element;
          if (c.elements_[ep].simplex.same_vertices(c.elements_[eq].simplex))
            throw std::invalid_argument("Connectivity::from_cells: cells " + std::to_string(std::min(ep, eq)) +
                                        " and " + std::to_string(std::max(ep, eq)) + " have the same vertices");
        }
      if (end - i > 2)
        throw std::invalid_argument("Connectivity::from_cells: face " + c.faces_[a].simplex.to_string() +
                                    " is shared by " + std::to_string(end - i) + " cells (" +
                                    std::to_string(ea) + ", " + std::to_string(eb) +
                                    ", ...): not a manifold mesh");
      if (c.faces_[a].simplex.sign() == c.faces_[b].simplex.sign())
        throw std::invalid_argument("Connectivity::from_cells: cells " + std::to_string(ea) + " and " +
                                    std::to_string(eb) + " lie on the same side of their common face " +
                                    c.faces_[a].simplex.to_string() + " (they overlap)");
      c.link(a, b);
    }
    i = end;
  }
  for (std::size_t e = 0; e < n_cells; ++e)
    for (VertexId v : c.elements_[e].simplex.vertices()) {
      c.ensure_vertex_capacity(v);
      ++c.vertex_uses_[v];
      c.vertex_element_[v] = static_cast<ElementId>(e);
    }
  return c;
}

bool Connectivity::already_kept(const Simplex& sigma, const LocalFaceMap& old_faces,
                                const std::unordered_set<ElementId>& old_set) const {
  if (boundary_.count(sigma)) return true;
  // An interior face σ of a kept element is the mate of -σ; seen from -σ if that is an old face.
  const auto minus = old_faces.find(sigma.mate());
  if (minus == old_faces.end()) return false;
  const FaceId mate = faces_[minus->second].mate;
  return mate != no_id && !old_set.count(faces_[mate].element);
}

bool Connectivity::is_element(ElementId e) const {
  return e >= 0 && e < element_capacity() && !elements_[e].simplex.empty();
}

bool Connectivity::is_face(FaceId f) const {
  return f >= 0 && f < face_capacity() && faces_[f].element != no_id;
}

FaceId Connectivity::opposite_face(ElementId e, VertexId v) const {
  const int j = elements_[e].simplex.index(v);
  return j < 0 ? no_id : elements_[e].faces[j];
}

VertexId Connectivity::opposite_vertex(ElementId e, FaceId f) const {
  const Element& element = elements_[e];
  for (int j = 0; j <= dim_; ++j)
    if (element.faces[j] == f) return element.simplex.vertex(j);
  return no_id;
}

ElementId Connectivity::neighbor(ElementId e, int j) const {
  const FaceId mate = faces_[elements_[e].faces[j]].mate;
  return mate == no_id ? no_id : faces_[mate].element;
}

std::vector<ElementId> Connectivity::element_ids() const {
  std::vector<ElementId> ids;
  ids.reserve(n_elements_);
  for (ElementId e = 0; e < element_capacity(); ++e)
    if (!elements_[e].simplex.empty()) ids.push_back(e);
  return ids;
}

ElementId Connectivity::allocate_element(const Simplex& simplex) {
  ElementId e;
  if (!free_elements_.empty()) {
    e = free_elements_.back();
    free_elements_.pop_back();
  } else {
    e = element_capacity();
    elements_.emplace_back();
  }
  elements_[e].simplex = simplex;
  ++n_elements_;
  return e;
}

FaceId Connectivity::allocate_face(const Simplex& simplex) {
  FaceId f;
  if (!free_faces_.empty()) {
    f = free_faces_.back();
    free_faces_.pop_back();
  } else {
    f = face_capacity();
    faces_.emplace_back();
  }
  faces_[f] = Face{simplex, no_id, no_id};
  return f;
}

void Connectivity::release_element(ElementId e) {
  elements_[e] = Element{};
  free_elements_.push_back(e);
  --n_elements_;
}

void Connectivity::release_face(FaceId f) {
  faces_[f] = Face{};
  free_faces_.push_back(f);
}

void Connectivity::link(FaceId a, FaceId b) {
  faces_[a].mate = b;
  faces_[b].mate = a;
}

std::vector<ElementId> Connectivity::replace_elements(std::span<const ElementId> old_elements,
                                                      std::span<const Simplex> new_simplexes) {
  // Checks first, so that a rejected call changes nothing.
  std::unordered_set<ElementId> old_set;
  LocalFaceMap old_faces;  // simplex -> Face of an old element
  for (ElementId e : old_elements) {
    if (!is_element(e)) throw std::invalid_argument("replace_elements: " + element_text(e) + " does not exist");
    if (!old_set.insert(e).second)
      throw std::invalid_argument("replace_elements: " + element_text(e) + " is listed twice");
    for (int j = 0; j <= dim_; ++j) old_faces.emplace(faces_[elements_[e].faces[j]].simplex, elements_[e].faces[j]);
  }
  LocalFaceMap new_faces;  // simplex -> Face (reused or created); filled with no_id for now
  for (const Simplex& tau : new_simplexes) {
    if (tau.dimension() != dim_)
      throw std::invalid_argument("replace_elements: simplex " + tau.to_string() + " has dimension " +
                                  std::to_string(tau.dimension()) + ", the mesh has " + std::to_string(dim_));
    for (int j = 0; j <= dim_; ++j) {
      const Simplex sigma = tau.subn(j);
      if (!new_faces.emplace(sigma, no_id))
        throw std::invalid_argument("replace_elements: face " + sigma.to_string() +
                                    " would belong to two new elements (7.4)");
      if (!old_faces.count(sigma) && already_kept(sigma, old_faces, old_set))
        throw std::invalid_argument("replace_elements: face " + sigma.to_string() +
                                    " already belongs to an element that stays (7.4)");
    }
  }

  ConnectivityChange change;
  // Discard old faces that do not occur again; their surviving mates become orphans that
  // join the boundary unless a new face pairs with them. Released only after all are
  // classified: a released face no longer tells whether it was discarded.
  std::vector<FaceId> orphans, discarded;
  for (const auto& [sigma, f] : old_faces) {
    if (new_faces.count(sigma)) continue;
    discarded.push_back(f);
    const FaceId mate = faces_[f].mate;
    if (mate != no_id) {
      const bool mate_discarded = old_faces.count(faces_[mate].simplex) && !new_faces.count(faces_[mate].simplex);
      if (!mate_discarded) {
        faces_[mate].mate = no_id;
        orphans.push_back(mate);
      }
    } else {
      boundary_.erase(sigma);
      change.boundary_removed.push_back(sigma);
    }
  }
  for (FaceId f : discarded) release_face(f);
  for (ElementId e : old_elements) {
    change.removed_elements.emplace_back(e, elements_[e].simplex);
    release_element(e);
  }

  std::vector<FaceId> created;
  std::vector<ElementId> added;
  added.reserve(new_simplexes.size());
  for (const Simplex& tau : new_simplexes) {
    const ElementId e = allocate_element(tau);
    added.push_back(e);
    for (int j = 0; j <= dim_; ++j) {
      const Simplex sigma = tau.subn(j);
      FaceId f;
      if (auto old = old_faces.find(sigma); old != old_faces.end()) {
        f = old->second;  // reused: pointers to this face stay valid (§7.3)
      } else {
        f = allocate_face(sigma);
        created.push_back(f);
      }
      faces_[f].element = e;
      elements_[e].faces[j] = f;
      new_faces.assign(sigma, f);
    }
  }
  // Pair created faces: first among the new faces (matched pairs never touch the boundary
  // map), then with the boundary; what stays unmatched joins the boundary.
  pair_faces(created, new_faces, orphans, change);
  change.added_elements = added;
  notify(change, orphans);
  return added;
}

void Connectivity::change_elements(std::span<const ElementSubstitution> substitutions) {
  std::unordered_set<ElementId> changed_set;
  std::vector<Simplex> new_simplexes;
  new_simplexes.reserve(substitutions.size());
  for (const ElementSubstitution& s : substitutions) {
    if (!is_element(s.element))
      throw std::invalid_argument("change_elements: " + element_text(s.element) + " does not exist");
    if (!changed_set.insert(s.element).second)
      throw std::invalid_argument("change_elements: " + element_text(s.element) + " is listed twice");
    try {
      new_simplexes.push_back(elements_[s.element].simplex.mapped(s));
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument("change_elements: the substitution is not injective on " +
                                  element_text(s.element) + " " + elements_[s.element].simplex.to_string());
    }
  }

  ConnectivityChange change;
  // Unlink every face of a changed element; a mate outside the change becomes an orphan.
  std::vector<FaceId> affected, orphans;
  for (const ElementSubstitution& s : substitutions) {
    for (int j = 0; j <= dim_; ++j) {
      const FaceId f = elements_[s.element].faces[j];
      affected.push_back(f);
      const FaceId mate = faces_[f].mate;
      if (mate == no_id) {
        boundary_.erase(faces_[f].simplex);
        change.boundary_removed.push_back(faces_[f].simplex);
      } else if (!changed_set.count(faces_[mate].element)) {
        faces_[mate].mate = no_id;
        orphans.push_back(mate);
      }
      faces_[f].mate = no_id;
    }
  }
  // Rename: the face opposite vertex v becomes the face opposite π(v), so (7.1) holds again.
  for (std::size_t i = 0; i < substitutions.size(); ++i) {
    const ElementSubstitution& s = substitutions[i];
    Element& element = elements_[s.element];
    const Simplex& tau_new = new_simplexes[i];
    std::array<FaceId, max_dimension + 1> faces{no_id, no_id, no_id, no_id};
    for (int j = 0; j <= dim_; ++j) {
      const int j_new = tau_new.index(s(element.simplex.vertex(j)));
      faces[j_new] = element.faces[j];
      faces_[element.faces[j]].simplex = tau_new.subn(j_new);
    }
    change.changed_elements.emplace_back(s.element, element.simplex);
    element.simplex = tau_new;
    element.faces = faces;
  }
  // Re-pair: affected faces and orphans with each other first, then with the boundary.
  BoundaryMap local;
  for (FaceId f : affected) local.emplace(faces_[f].simplex, f);
  for (FaceId g : orphans) local.emplace(faces_[g].simplex, g);
  pair_faces(affected, local, orphans, change);
  notify(change, orphans);
}

template <class FaceMap>
void Connectivity::pair_faces(std::span<const FaceId> unmatched, const FaceMap& local,
                              std::span<const FaceId> orphans, ConnectivityChange& change) {
  for (FaceId f : unmatched) {
    if (faces_[f].mate != no_id) continue;
    const Simplex minus = faces_[f].simplex.mate();
    if (auto partner = local.find(minus); partner != local.end() && faces_[partner->second].mate == no_id) {
      if (boundary_.erase(minus)) change.boundary_removed.push_back(minus);  // a reused boundary face
      link(f, partner->second);
    } else if (auto b = boundary_.find(minus); b != boundary_.end()) {
      link(f, b->second);
      change.boundary_removed.push_back(minus);
      boundary_.erase(b);
    } else {
      boundary_.emplace(faces_[f].simplex, f);
      change.boundary_added.push_back(f);
    }
  }
  for (FaceId g : orphans) {
    if (faces_[g].mate != no_id) continue;
    boundary_.emplace(faces_[g].simplex, g);
    change.boundary_added.push_back(g);
  }
}

std::int32_t Connectivity::n_vertex_uses(VertexId v) const {
  return v >= 0 && static_cast<std::size_t>(v) < vertex_uses_.size() ? vertex_uses_[v] : 0;
}

ElementId Connectivity::vertex_element(VertexId v) const {
  return v >= 0 && static_cast<std::size_t>(v) < vertex_element_.size() ? vertex_element_[v] : no_id;
}

void Connectivity::ensure_vertex_capacity(VertexId v) {
  if (static_cast<std::size_t>(v) >= vertex_uses_.size()) {
    vertex_uses_.resize(static_cast<std::size_t>(v) + 1, 0);
    vertex_element_.resize(static_cast<std::size_t>(v) + 1, no_id);
  }
}

void Connectivity::update_vertex_incidence(const ConnectivityChange& change, std::span<const FaceId> orphans) {
  std::vector<VertexId> lost;  // vertices whose element hint may have died
  auto leave = [&](const Simplex& s) {
    for (VertexId v : s.vertices()) {
      --vertex_uses_[v];
      lost.push_back(v);
    }
  };
  auto enter = [&](ElementId e) {
    for (VertexId v : elements_[e].simplex.vertices()) {
      ensure_vertex_capacity(v);
      ++vertex_uses_[v];
      vertex_element_[v] = e;
    }
  };
  for (const auto& [e, simplex] : change.removed_elements) leave(simplex);
  for (const auto& [e, old_simplex] : change.changed_elements) {
    leave(old_simplex);
    enter(e);
  }
  for (ElementId e : change.added_elements) enter(e);
  for (VertexId v : lost) {
    ElementId& hint = vertex_element_[v];
    if (vertex_uses_[v] == 0) {
      hint = no_id;
      continue;
    }
    if (is_element(hint) && elements_[hint].simplex.contains(v)) continue;
    // A surviving element next to the changed ones (its face lost its mate) contains v
    // whenever v's star is connected through faces; otherwise (a pinched star) scan.
    hint = no_id;
    for (FaceId g : orphans)
      if (is_face(g) && faces_[g].simplex.contains(v)) {
        hint = faces_[g].element;
        break;
      }
    for (ElementId e = 0; hint == no_id && e < element_capacity(); ++e)
      if (is_element(e) && elements_[e].simplex.contains(v)) hint = e;
  }
}

void Connectivity::stage_vertex_event(VertexEvent event) {
  ensure_vertex_capacity(event.vertex);
  staged_vertex_events_.push_back(std::move(event));
}

void Connectivity::notify_vertex_events() {
  if (staged_vertex_events_.empty()) return;
  ConnectivityChange change;
  notify(change, {});
}

namespace {

// Live elements around the moved vertices that are not otherwise reported as new or changed.
std::vector<ElementId> reshaped_by(const Connectivity& c, const ConnectivityChange& change) {
  const bool moved = std::any_of(change.vertex_events.begin(), change.vertex_events.end(),
                                 [](const VertexEvent& event) { return event.kind == VertexEventKind::moved; });
  if (!moved) return {};  // the usual case: no sets to build
  std::unordered_set<ElementId> reported(change.added_elements.begin(), change.added_elements.end());
  for (const auto& entry : change.changed_elements) reported.insert(entry.first);
  std::unordered_set<ElementId> reshaped;
  for (const VertexEvent& event : change.vertex_events) {
    if (event.kind != VertexEventKind::moved || c.vertex_element(event.vertex) == no_id) continue;
    for (ElementId e : vertex_star(c, event.vertex, c.vertex_element(event.vertex)))
      if (!reported.count(e)) reshaped.insert(e);
  }
  std::vector<ElementId> sorted(reshaped.begin(), reshaped.end());
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

}  // namespace

void Connectivity::notify(ConnectivityChange& change, std::span<const FaceId> orphans) {
  change.vertex_events = std::move(staged_vertex_events_);
  staged_vertex_events_.clear();
  update_vertex_incidence(change, orphans);
  change.reshaped_elements = reshaped_by(*this, change);
  ++revision_;
  const bool moves_only =
      change.removed_elements.empty() && change.added_elements.empty() && change.changed_elements.empty() &&
      std::all_of(change.vertex_events.begin(), change.vertex_events.end(),
                  [](const VertexEvent& event) { return event.kind == VertexEventKind::moved; });
  if (!moves_only) ++topology_revision_;
  for (const auto& [watcher, mode] : watchers_)
    if (!in_batch() || mode == WatchMode::each_operation) watcher->on_change(*this, change);
  if (in_batch()) merge_into_batch(change);
}

void Connectivity::merge_into_batch(const ConnectivityChange& change) {
  for (const auto& [e, simplex] : change.removed_elements) {
    if (batch_added_.erase(e)) continue;  // born and gone within the batch
    if (auto it = batch_changed_.find(e); it != batch_changed_.end()) {
      batch_.removed_elements.emplace_back(e, batch_.changed_elements[it->second].second);
      batch_.changed_elements[it->second].first = no_id;
      batch_changed_.erase(it);
    } else {
      batch_.removed_elements.emplace_back(e, simplex);
    }
  }
  for (ElementId e : change.added_elements) {
    batch_added_.insert(e);
    batch_.added_elements.push_back(e);
  }
  for (const auto& [e, old_simplex] : change.changed_elements) {
    if (batch_added_.count(e) || batch_changed_.count(e)) continue;
    batch_changed_.emplace(e, batch_.changed_elements.size());
    batch_.changed_elements.emplace_back(e, old_simplex);
  }
  batch_.boundary_removed.insert(batch_.boundary_removed.end(), change.boundary_removed.begin(),
                                 change.boundary_removed.end());
  batch_.boundary_added.insert(batch_.boundary_added.end(), change.boundary_added.begin(), change.boundary_added.end());
  batch_.vertex_events.insert(batch_.vertex_events.end(), change.vertex_events.begin(), change.vertex_events.end());
}

ConnectivityChange Connectivity::take_batch() {
  ConnectivityChange merged = std::move(batch_);
  batch_ = ConnectivityChange{};
  std::vector<ElementId> added;
  for (ElementId e : merged.added_elements)
    if (batch_added_.erase(e)) added.push_back(e);  // each live one once
  merged.added_elements = std::move(added);
  std::erase_if(merged.changed_elements, [](const auto& entry) { return entry.first == no_id; });
  std::vector<FaceId> entered;
  std::unordered_set<FaceId> seen;
  for (FaceId f : merged.boundary_added)
    if (is_face(f) && faces_[f].mate == no_id && seen.insert(f).second) entered.push_back(f);
  merged.boundary_added = std::move(entered);
  std::vector<Simplex> left;
  std::unordered_set<Simplex, SimplexHash> seen_simplex;
  for (const Simplex& sigma : merged.boundary_removed)
    if (!boundary_.count(sigma) && seen_simplex.insert(sigma).second) left.push_back(sigma);
  merged.boundary_removed = std::move(left);
  merged.reshaped_elements = reshaped_by(*this, merged);
  batch_added_.clear();
  batch_changed_.clear();
  return merged;
}

void Connectivity::begin_batch() { ++batch_depth_; }

void Connectivity::end_batch() {
  if (batch_depth_ == 0) throw std::logic_error("end_batch without begin_batch");
  if (batch_depth_ == 1) notify_vertex_events();  // vertex events staged but not yet delivered
  if (--batch_depth_ > 0) return;
  ConnectivityChange merged = take_batch();
  if (merged.empty()) return;
  for (const auto& [watcher, mode] : watchers_)
    if (mode == WatchMode::merged) watcher->on_change(*this, merged);
}

ChangeBatch::~ChangeBatch() noexcept(false) {
  if (std::uncaught_exceptions() == 0) {
    c_.end_batch();
    return;
  }
  try {  // already unwinding: deliver what was done, but do not throw a second exception
    c_.end_batch();
  } catch (...) {
  }
}

void Connectivity::add_watcher(ConnectivityWatcher* watcher, WatchMode mode) {
  watchers_.emplace_back(watcher, mode);
  watcher->init(*this);
}

std::string Connectivity::watcher_refusal(const Simplex& cell) const {
  for (const auto& [watcher, mode] : watchers_)
    if (std::string why = watcher->refuses(cell); !why.empty()) return why;
  return {};
}

void Connectivity::remove_watcher(ConnectivityWatcher* watcher) {
  std::erase_if(watchers_, [watcher](const auto& entry) { return entry.first == watcher; });
}

std::size_t Connectivity::memory_bytes() const {
  // unordered_map: one node (key, value, next pointer, cached hash) per entry plus buckets.
  const std::size_t boundary_node = sizeof(Simplex) + sizeof(FaceId) + 2 * sizeof(void*);
  return elements_.capacity() * sizeof(Element) + faces_.capacity() * sizeof(Face) +
         (free_elements_.capacity() + free_faces_.capacity() + vertex_uses_.capacity() +
          vertex_element_.capacity()) * sizeof(std::int32_t) +
         boundary_.size() * boundary_node + boundary_.bucket_count() * sizeof(void*);
}

}  // namespace snede
