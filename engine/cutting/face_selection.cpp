#include "cutting/face_selection.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "mesh/element_quality.hpp"

namespace snede {

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

FaceSelection FaceSelector::select(const Connectivity& c, const DeformedPositions& x, const SweepTriangle& sweep) {
  sweeps_.push_back(sweep);
  if (sweeps_.size() > remembered_sweeps) sweeps_.pop_front();
  FaceSelection selection;
  selection.touched = walk(c, x, sweep, seeds(c, x, sweep));

  // The tetrahedra that may be completed now: those met by this sweep and the previous one.
  std::vector<ElementId> candidates = selection.touched;
  for (ElementId e : previous_touched_)
    if (c.is_element(e)) candidates.push_back(e);
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());

  // The marked end of each edge of the candidates, from its first crossing among the
  // remembered sweeps (−1: not crossed), and the sweep that marked it.
  struct Mark {
    VertexId node = no_id;
    int sweep = -1;
  };
  std::unordered_map<std::uint64_t, Mark> marks;
  auto mark_of = [&](VertexId a, VertexId b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
    auto [it, fresh] = marks.try_emplace(key);
    if (!fresh) return it->second;
    const Point3 pa = x(a), pb = x(b);
    Point3 lo, hi;
    for (int k = 0; k < 3; ++k) lo[k] = std::min(pa[k], pb[k]), hi[k] = std::max(pa[k], pb[k]);
    for (std::size_t s = 0; s < sweeps_.size(); ++s)
      if (sweeps_[s].box_overlaps(lo, hi))
        if (const std::optional<double> t = sweeps_[s].crossing(pa, pb)) {
          it->second = {*t < 0.5 ? a : *t > 0.5 ? b : std::min(a, b), static_cast<int>(s)};
          break;
        }
    return it->second;
  };

  std::unordered_set<FaceId> chosen;
  for (ElementId e : candidates) {
    const Simplex& tet = c.element(e).simplex;
    std::array<int, 4> marked_by{-1, -1, -1, -1};
    for (const auto& [i, j] : tetrahedron_edges) {
      const Mark m = mark_of(tet.vertex(i), tet.vertex(j));  // a < b: simplex vertices are sorted
      if (m.node == no_id) continue;
      int& by = marked_by[tet.index(m.node)];
      if (by < 0 || m.sweep < by) by = m.sweep;
    }
    const int n_marked = static_cast<int>(std::count_if(marked_by.begin(), marked_by.end(), [](int s) { return s >= 0; }));
    if (n_marked < 3) continue;
    int left_out = static_cast<int>(std::find(marked_by.begin(), marked_by.end(), -1) - marked_by.begin());
    if (n_marked == 4) {
      // Only when a sweep halves the edges exactly (§3.2.1): keep the three corners closest
      // to this sweep's plane (the thesis picks a face at random).
      double farthest = -1;
      for (int k = 0; k < 4; ++k)
        if (const double d = std::abs(sweep.signed_distance(x(tet.vertex(k)))); d > farthest) farthest = d, left_out = k;
    }
    const FaceId f = c.opposite_face(e, tet.vertex(left_out));
    const FaceId mate = c.face(f).mate;
    if (mate == no_id) continue;  // already on the surface: nothing to dissect
    if (!chosen.insert(std::min(f, mate)).second) continue;
    selection.faces.push_back(std::min(f, mate));
    for (int k = 0; k < 4; ++k)
      if (k != left_out) selection.plane.try_emplace(tet.vertex(k), sweeps_[marked_by[k]]);
  }
  std::sort(selection.faces.begin(), selection.faces.end());
  previous_touched_ = selection.touched;
  return selection;
}

}  // namespace snede
