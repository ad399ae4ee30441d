#include "cutting/face_selection.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "mesh/element_quality.hpp"
#include "mesh/traversal.hpp"

namespace snede {

std::vector<ElementId> FaceSelector::seeds(const Connectivity& c, const DeformedPositions& x,
                                           const SweepTriangle& sweep) const {
  std::vector<ElementId> found;
  for (ElementId e : previous_touched_)
    if (c.is_element(e) && sweep.meets_tetrahedron(x.corners(c.element(e).simplex))) found.push_back(e);
  // And the boundary faces the sweep meets: the first contact, and every later one where the
  // blade enters the body again apart from where it already is (the other side of a torus's
  // ring, a second lobe), which no walk from the tetrahedra met so far reaches.
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

  // Every vertex a crossing marks, with the earliest sweep that marked it. Once the marked
  // vertices are snapped onto the sweep, no edge crosses it any more, so each tetrahedron
  // near the sweep lies on one side of it, or on it (all four corners marked).
  std::unordered_map<VertexId, int> marked_by;
  std::unordered_map<VertexId, ElementId> marked_in;  // a tetrahedron with the vertex, for its star
  const auto mark_edges_of = [&](std::span<const ElementId> tets) {
    for (ElementId e : tets) {
      const Simplex& tet = c.element(e).simplex;
      for (const auto& [i, j] : tetrahedron_edges) {
        const Mark m = mark_of(tet.vertex(i), tet.vertex(j));  // a < b: simplex vertices are sorted
        if (m.node == no_id) continue;
        auto [it, fresh] = marked_by.try_emplace(m.node, m.sweep);
        if (!fresh) it->second = std::min(it->second, m.sweep);
        marked_in.try_emplace(m.node, e);
      }
    }
  };
  mark_edges_of(candidates);
  // A face whose last corner this sweep marks may lie in a tetrahedron no recent sweep met:
  // the stars of the marked vertices are candidates too, or the surface keeps a hole there.
  {
    std::unordered_set<ElementId> known(candidates.begin(), candidates.end());
    std::vector<ElementId> stars;
    for (const auto& [v, e0] : marked_in)
      for (ElementId e : vertex_star(c, v, e0))
        if (known.insert(e).second) stars.push_back(e);
    mark_edges_of(stars);
    candidates.insert(candidates.end(), stars.begin(), stars.end());
  }
  const auto is_marked = [&](VertexId v) { return marked_by.count(v) > 0; };
  // The side of `plane` a tetrahedron is on: that of its corners neither marked nor on the
  // plane (0 if they are on both sides: beyond the sweep's edge, where no crossing marked
  // them), or of its centroid when there are none.
  const auto side = [&](const Simplex& tet, const SweepTriangle& plane) {
    const std::array<Point3, 4> corners = x.corners(tet);
    std::array<double, 12> flat;
    for (int i = 0; i < 4; ++i) std::copy(corners[i].begin(), corners[i].end(), flat.begin() + 3 * i);
    // A corner snapped onto this plane by an earlier sweep is on it (to rounding), marked or not.
    const double on_plane = 1e-9 * cell_longest_edge(3, 3, flat);
    int found = 0;
    bool any_unmarked = false;
    Point3 centroid{0, 0, 0};
    for (int i = 0; i < 4; ++i) {
      for (int k = 0; k < 3; ++k) centroid[k] += corners[i][k] / 4;
      const double d = plane.signed_distance(corners[i]);
      if (is_marked(tet.vertex(i)) || std::abs(d) <= on_plane) continue;
      any_unmarked = true;
      const int sign = d > 0 ? 1 : -1;
      if (found != 0 && sign != found) return 0;
      found = sign;
    }
    if (any_unmarked) return found;
    const double d = plane.signed_distance(centroid);
    return (d > 0) - (d < 0);
  };

  // §3.2.1 selects the face a tetrahedron's marked corners span. Here a face is cut when its
  // three corners are marked and the tetrahedra on its two sides are on opposite sides of
  // the sweep that marked it last: the faces between the two sides, which close up into one
  // surface wherever the sweeps cross the body, so a sweep across the whole body separates it.
  // (Faces chosen tetrahedron by tetrahedron left holes where two or four corners were
  // marked, and the body stayed joined across them.)
  std::unordered_set<FaceId> chosen;
  for (ElementId e : candidates) {
    const Simplex& tet = c.element(e).simplex;
    for (int k = 0; k < 4; ++k) {
      const FaceId f = c.opposite_face(e, tet.vertex(k));
      const FaceId mate = c.face(f).mate;
      if (mate == no_id) continue;  // already on the surface: nothing to dissect
      const Simplex& face = c.face(f).simplex;
      int last = -1;
      bool all_marked = true;
      for (VertexId v : face.vertices()) {
        const auto it = marked_by.find(v);
        if (it == marked_by.end()) {
          all_marked = false;
          break;
        }
        last = std::max(last, it->second);
      }
      if (!all_marked || chosen.count(std::min(f, mate))) continue;
      const SweepTriangle& plane = sweeps_[last];
      const int here = side(tet, plane), there = side(c.element(c.face(mate).element).simplex, plane);
      if (here * there >= 0) continue;
      chosen.insert(std::min(f, mate));
      selection.faces.push_back(std::min(f, mate));
      for (VertexId v : face.vertices()) selection.plane.try_emplace(v, sweeps_[marked_by[v]]);
    }
  }
  std::sort(selection.faces.begin(), selection.faces.end());
  previous_touched_ = selection.touched;
  return selection;
}

}  // namespace snede
