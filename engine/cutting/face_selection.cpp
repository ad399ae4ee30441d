#include "cutting/face_selection.hpp"

#include <algorithm>
#include <cmath>

#include "mesh/element_quality.hpp"

namespace snede {

std::uint64_t FaceSelector::edge_key(VertexId a, VertexId b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

std::vector<ElementId> FaceSelector::seeds(const Connectivity& c, const DeformedPositions& x,
                                           const SweepTriangle& sweep) const {
  std::vector<ElementId> found;
  for (ElementId e : previous_touched_)
    if (c.is_element(e) && sweep.meets_tetrahedron(x.corners(c.element(e).simplex))) found.push_back(e);
  if (!found.empty()) return found;
  // First contact: the boundary faces the sweep meets.
  for (const auto& [simplex, f] : c.boundary()) {
    const Point3 a = x(simplex.vertex(0)), b = x(simplex.vertex(1)), d = x(simplex.vertex(2));
    Point3 lo = a, hi = a;
    for (const Point3* p : {&b, &d})
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], (*p)[k]), hi[k] = std::max(hi[k], (*p)[k]);
    if (sweep.box_overlaps(lo, hi) && sweep.meets_triangle(a, b, d)) found.push_back(c.face(f).element);
  }
  if (!found.empty()) return found;
  // A sweep wholly inside the body, with no previous contact.
  for (ElementId e = 0; e < c.element_capacity(); ++e)
    if (c.is_element(e) && sweep.meets_tetrahedron(x.corners(c.element(e).simplex))) return {e};
  return {};
}

std::vector<ElementId> FaceSelector::walk(const Connectivity& c, const DeformedPositions& x,
                                          const SweepTriangle& sweep, std::vector<ElementId> stack) const {
  // The closed tetrahedra meeting the closed triangle are face-connected (touching counts),
  // so a walk across faces from any of them finds them all.
  std::unordered_set<ElementId> seen(stack.begin(), stack.end());
  std::vector<ElementId> met;
  while (!stack.empty()) {
    const ElementId e = stack.back();
    stack.pop_back();
    met.push_back(e);
    for (int j = 0; j < 4; ++j) {
      const ElementId n = c.neighbor(e, j);
      if (n == no_id || !seen.insert(n).second) continue;
      if (sweep.meets_tetrahedron(x.corners(c.element(n).simplex))) stack.push_back(n);
    }
  }
  std::sort(met.begin(), met.end());
  return met;
}

FaceSelection FaceSelector::select(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep,
                                   int sweep_index) {
  FaceSelection selection;
  selection.touched = walk(c, x, sweep, seeds(c, x, sweep));
  for (ElementId e : selection.touched) {
    const Simplex& tet = c.element(e).simplex;
    for (const auto& [i, j] : tetrahedron_edges) {
      const VertexId a = tet.vertex(i), b = tet.vertex(j);  // a < b: simplex vertices are sorted
      if (marks_.count(edge_key(a, b))) continue;           // only the first crossing counts
      const std::optional<double> t = sweep.crossing(x(a), x(b));
      if (!t) continue;
      const VertexId node = *t < 0.5 ? a : *t > 0.5 ? b : std::min(a, b);
      marks_.emplace(edge_key(a, b), Mark{node, sweep_index});
      node_sweep_.emplace(node, sweep_index);
      ++selection.edges_crossed;
    }
  }
  std::unordered_set<FaceId> chosen;
  for (ElementId e : selection.touched) {
    const Simplex& tet = c.element(e).simplex;
    std::array<bool, 4> marked{};
    for (const auto& [i, j] : tetrahedron_edges)
      if (const auto it = marks_.find(edge_key(tet.vertex(i), tet.vertex(j))); it != marks_.end())
        marked[tet.index(it->second.node)] = true;
    const int n_marked = static_cast<int>(std::count(marked.begin(), marked.end(), true));
    if (n_marked < 3) continue;
    int left_out = static_cast<int>(std::find(marked.begin(), marked.end(), false) - marked.begin());
    if (n_marked == 4) {
      // Only when the sweep halves the edges exactly (§3.2.1): keep the three corners
      // closest to this sweep's plane (the thesis picks a face at random).
      ++selection.four_marked;
      double farthest = -1;
      for (int k = 0; k < 4; ++k)
        if (const double d = std::abs(sweep.signed_distance(x(tet.vertex(k)))); d > farthest) farthest = d, left_out = k;
    }
    const FaceId f = c.opposite_face(e, tet.vertex(left_out));
    const FaceId mate = c.face(f).mate;
    if (mate == no_id) continue;  // already on the surface: nothing to dissect
    if (chosen.insert(std::min(f, mate)).second) selection.faces.push_back(std::min(f, mate));
  }
  std::sort(selection.faces.begin(), selection.faces.end());
  std::vector<ElementId> remembered = selection.touched;
  for (ElementId e : previous_touched_)
    if (c.is_element(e)) remembered.push_back(e);
  keep_marks_of(c, remembered);
  previous_touched_ = selection.touched;
  return selection;
}

void FaceSelector::keep_marks_of(const Connectivity& c, const std::vector<ElementId>& elements) {
  // Marks matter only for the tetrahedra the scalpel may still complete: those met by the
  // last two sweeps. Dropping the rest keeps the memory (and every later update) local.
  std::unordered_map<std::uint64_t, Mark> kept;
  for (ElementId e : elements) {
    const Simplex& tet = c.element(e).simplex;
    for (const auto& [i, j] : tetrahedron_edges)
      if (const auto it = marks_.find(edge_key(tet.vertex(i), tet.vertex(j))); it != marks_.end()) kept.insert(*it);
  }
  marks_ = std::move(kept);
  std::unordered_map<VertexId, int> nodes;
  for (const auto& [key, mark] : marks_)
    if (const auto it = node_sweep_.find(mark.node); it != node_sweep_.end()) nodes.insert(*it);
  node_sweep_ = std::move(nodes);
}

int FaceSelector::marking_sweep(VertexId v) const {
  const auto it = node_sweep_.find(v);
  return it == node_sweep_.end() ? -1 : it->second;
}

int FaceSelector::oldest_sweep() const {
  int oldest = -1;
  for (const auto& [v, sweep] : node_sweep_)
    if (oldest < 0 || sweep < oldest) oldest = sweep;
  return oldest;
}

void FaceSelector::forget_vertex(VertexId v) {
  std::erase_if(marks_, [v](const auto& entry) {
    return static_cast<VertexId>(entry.first >> 32) == v || static_cast<VertexId>(entry.first & 0xffffffffu) == v;
  });
  node_sweep_.erase(v);
}

void FaceSelector::copy_vertex(VertexId original, VertexId copy) {
  // Edges of the copy that do not exist are never looked up, and the next selection drops them.
  std::vector<std::pair<std::uint64_t, Mark>> added;
  for (const auto& [key, mark] : marks_) {
    const VertexId a = static_cast<VertexId>(key >> 32), b = static_cast<VertexId>(key & 0xffffffffu);
    if (a != original && b != original) continue;
    const VertexId other = a == original ? b : a;
    added.push_back({edge_key(copy, other), Mark{mark.node == original ? copy : mark.node, mark.sweep}});
  }
  for (const auto& entry : added) marks_.insert(entry);
  if (const auto it = node_sweep_.find(original); it != node_sweep_.end()) node_sweep_.emplace(copy, it->second);
}

}  // namespace snede
