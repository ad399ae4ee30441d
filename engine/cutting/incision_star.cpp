#include "cutting/incision_star.hpp"

#include <algorithm>
#include <string>

#include "core/petsc_util.hpp"
#include "topology/local_star.hpp"

namespace snede {

std::vector<Wedge> star_wedges(const Connectivity& c, VertexId b) {
  std::vector<Wedge> result;
  for (ElementId e : local_star(c, b).elements) {
    const auto t = c.element(e).simplex.oriented_vertices();
    const int i = static_cast<int>(std::find(t.begin(), t.begin() + 3, b) - t.begin());
    result.push_back({e, t[(i + 1) % 3], t[(i + 2) % 3]});
  }
  return result;
}

bool is_boundary_edge(const Connectivity& c, ElementId triangle, VertexId opposite) {
  return c.face(c.opposite_face(triangle, opposite)).mate == no_id;
}

bool touches_boundary(const Connectivity& c, VertexId v) {
  for (ElementId e : local_star(c, v).elements)
    for (VertexId w : c.element(e).simplex.vertices())
      if (w != v && is_boundary_edge(c, e, w)) return true;
  return false;
}

std::vector<VertexId> lip_edges(const Connectivity& c, const std::unordered_set<VertexId>& incision_vertices) {
  std::vector<VertexId> edges;
  for (const auto& [simplex, f] : c.boundary()) {
    const auto v = simplex.oriented_vertices();
    if (incision_vertices.count(v[0]) && incision_vertices.count(v[1])) edges.insert(edges.end(), {v[0], v[1]});
  }
  return edges;
}

std::vector<VertexId> boundary_neighbours(const Connectivity& c, VertexId v) {
  std::vector<VertexId> ends;
  if (c.n_vertex_uses(v) == 0) return ends;
  for (const Wedge& w : star_wedges(c, v))
    for (const auto& [end, opposite] : {std::pair{w.y, w.z}, std::pair{w.z, w.y}})
      if (is_boundary_edge(c, w.element, opposite)) ends.push_back(end);
  return ends;
}

bool is_incision_tip(const Mesh& mesh, VertexId v, const std::unordered_set<VertexId>& incision_vertices,
                     bool taking_over) {
  const std::vector<VertexId> ends = boundary_neighbours(mesh.connectivity(), v);
  if (ends.size() != 2 || !incision_vertices.count(ends[0]) || !incision_vertices.count(ends[1])) return false;
  if (!taking_over) return true;
  double along = 0;
  const auto x = mesh.point(v), p = mesh.point(ends[0]), q = mesh.point(ends[1]);
  for (std::size_t k = 0; k < x.size(); ++k) along += (p[k] - x[k]) * (q[k] - x[k]);
  return along > 0;
}

IncisionWatch::IncisionWatch(Connectivity& connectivity, std::unordered_set<VertexId>& incision_vertices,
                             Settled settled, VertexEventHook on_vertex_event)
    : connectivity_(connectivity),
      incision_(incision_vertices),
      settled_(std::move(settled)),
      on_vertex_event_(std::move(on_vertex_event)) {
  // The recorder first: an operation outside a batch is recorded before it is settled.
  connectivity_.add_watcher(&recorder_, WatchMode::each_operation);
  connectivity_.add_watcher(&settler_, WatchMode::merged);
}

IncisionWatch::~IncisionWatch() {
  connectivity_.remove_watcher(&settler_);
  connectivity_.remove_watcher(&recorder_);
}

void IncisionWatch::follow(std::span<const VertexId> actives) {
  heir_of_.clear();
  fates_.clear();
  for (VertexId a : actives) heir_of_[a] = a;
}

IncisionWatch::Fate& IncisionWatch::fate_of(VertexId active) {
  const auto [it, fresh] = fates_.try_emplace(active);
  if (fresh) it->second.heirs = {active};
  return it->second;
}

void IncisionWatch::forget(VertexId v) {
  incision_.erase(v);
  for (std::unordered_set<VertexId>* set : plain_sets_) set->erase(v);
  const auto followed = heir_of_.find(v);
  if (followed == heir_of_.end()) return;
  Fate& fate = fate_of(followed->second);
  std::erase(fate.heirs, v);
  fate.change += (fate.change.empty() ? "vertex " : "; vertex ") + std::to_string(v) + " was removed";
  heir_of_.erase(followed);
}

void IncisionWatch::inherit(VertexId x, VertexId u, const std::string& how) {
  const auto followed = heir_of_.find(x);
  if (followed == heir_of_.end()) return;
  const VertexId active = followed->second;
  Fate& fate = fate_of(active);
  if (std::find(fate.heirs.begin(), fate.heirs.end(), u) != fate.heirs.end()) return;
  fate.heirs.push_back(u);
  heir_of_.try_emplace(u, active);
  fate.change += (fate.change.empty() ? "vertex " : "; vertex ") + std::to_string(x) + how + std::to_string(u);
}

void IncisionWatch::record(const Connectivity& c, const ConnectivityChange& change) {
  if (own_ > 0) return;
  changed_ = true;
  entered_.insert(entered_.end(), change.boundary_added.begin(), change.boundary_added.end());
  std::unordered_map<VertexId, VertexId> original_of;  // this operation's dissection copies
  for (const VertexEvent& event : change.vertex_events) {
    if (on_vertex_event_) on_vertex_event_(event);
    const VertexId v = event.vertex;
    if (event.kind == VertexEventKind::removed) forget(v);
    if (event.kind == VertexEventKind::added && event.parents.count() == 1) {
      original_of[v] = event.parents.vertex.front();
      inherit(event.parents.vertex.front(), v, " was split by a dissection into itself and ");
    }
  }
  // §7.3: change_elements substitutes vertices; in each element, the vertex that left is taken
  // over by the one that came (a collapse's survivor, or a dissection's copy).
  for (const auto& [e, before] : change.changed_elements) {
    if (!c.is_element(e)) continue;
    const Simplex& after = c.element(e).simplex;
    std::vector<VertexId> left, came;
    for (VertexId v : before.vertices())
      if (!after.contains(v)) left.push_back(v);
    for (VertexId v : after.vertices())
      if (!before.contains(v)) came.push_back(v);
    for (VertexId x : left) {
      VertexId by = -1;
      for (VertexId u : came)
        if (came.size() == 1 || (original_of.count(u) && original_of.at(u) == x)) by = u;
      if (by >= 0) inherit(x, by, " was merged into vertex ");
    }
  }
}

void IncisionWatch::join_new_lips(const Connectivity& c) {
  std::unordered_set<Simplex, SimplexHash> entered;  // edges, either orientation
  for (FaceId f : entered_)
    if (c.is_face(f) && c.face(f).mate == no_id) entered.insert(c.face(f).simplex.mate()), entered.insert(c.face(f).simplex);
  entered_.clear();
  const auto is_new = [&](VertexId a, VertexId b) { return entered.count(Simplex(1, {a, b})) > 0; };
  std::vector<std::pair<VertexId, VertexId>> starts;  // (incision vertex, a new boundary edge's other end)
  for (const Simplex& edge : entered)
    for (const auto& [a, b] : {std::pair{edge.vertex(0), edge.vertex(1)}, std::pair{edge.vertex(1), edge.vertex(0)}})
      if (incision_.count(a) && !incision_.count(b)) starts.emplace_back(a, b);
  for (const auto& [from, first] : starts) {
    // Walk the new boundary edges from `from` through vertices with two boundary edges.
    std::vector<VertexId> between;
    VertexId previous = from, here = first;
    while (!incision_.count(here) && between.size() < 256) {
      between.push_back(here);
      const std::vector<VertexId> ends = boundary_neighbours(c, here);
      if (ends.size() != 2) break;
      const VertexId next = ends[0] == previous ? ends[1] : ends[0];
      if (!is_new(here, next)) break;
      previous = here;
      here = next;
    }
    if (incision_.count(here)) incision_.insert(between.begin(), between.end());
  }
}

void IncisionWatch::settle() {
  if (!changed_ || own_ > 0) return;
  changed_ = false;
  const Connectivity& c = connectivity_;
  join_new_lips(c);
  Fates fates = std::move(fates_);
  for (auto& [active, fate] : fates)
    std::erase_if(fate.heirs, [&](VertexId v) { return c.n_vertex_uses(v) == 0; });
  follow({});
  settled_(c, fates);
}

void IncisionWatch::lose(std::string why) { lost_ += (lost_.empty() ? "" : "; ") + why; }

void IncisionWatch::settle_before_move() {
  settle();
  if (lost_.empty()) return;
  const std::string why = std::move(lost_);
  lost_.clear();
  throw IncisionLost(why);
}

// The watch settles before OwnEdits counts what follows as the cutter's own.
IncisionWatch& CutterMove::settled(IncisionWatch& watch) {
  watch.settle_before_move();
  return watch;
}

CutterMove::CutterMove(IncisionWatch& watch, const Mesh& mesh)
    : mesh_(mesh), own_(settled(watch)), start_(wall_seconds()) {
  report_.moves = 1;
  report_.triangles_before = mesh.n_cells();
}

PlanarCutResult CutterMove::finished() {
  report_.triangles_after = mesh_.n_cells();
  report_.seconds = wall_seconds() - start_;
  return report_;
}

}  // namespace snede
