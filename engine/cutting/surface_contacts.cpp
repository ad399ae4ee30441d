// Where a moving scalpel first touches a surface away from the incisions it is cutting
// (§5.3.2, Figure 5.12): the three ways in.
#include <algorithm>

#include "core/predicates.hpp"
#include "cutting/surface_cutter.hpp"
#include "cutting/swept_intersections.hpp"

namespace snede {
namespace {

// A weight above this is off the triangle's side (relative to the triangle: weights are
// fractions).
constexpr double inside_weight = 1e-9;

// Where after a crossing at `time` the scalpel is looked at: just after, halfway, and at the
// end of the step (a boundary edge counts as entered if the scalpel goes into its triangle).
constexpr std::array<double, 3> later_fractions{1e-3, 0.25, 1.0};

// Whether segment p→q lies in the plane of triangle x (a scalpel flat on the surface touches it
// along a piece, not at a point: neither its ends nor its sweep enter anywhere new there).
bool in_plane(const Point3& p, const Point3& q, const std::array<Point3, 3>& x) {
  return orientation_3d(x[0].data(), x[1].data(), x[2].data(), p.data()) == 0 &&
         orientation_3d(x[0].data(), x[1].data(), x[2].data(), q.data()) == 0;
}

}  // namespace

bool SurfaceCutter::meets_inside(const Segment& scalpel, ElementId triangle, int corner) const {
  const auto o = mesh_.connectivity().element(triangle).simplex.oriented_vertices();
  const Point3 a = deformed(o[0]);
  const auto hit = segment_meets_triangle(scalpel.head, scalpel.tail, a, deformed(o[1]), deformed(o[2]), scalpel.head);
  if (!hit) return false;
  if (corner >= 0) return hit->weights[corner] > inside_weight;
  return *std::min_element(hit->weights.begin(), hit->weights.end()) > inside_weight;
}

std::vector<SurfaceCutter::Contact> SurfaceCutter::first_contacts(const Segment& from, const Segment& to) {
  const Connectivity& c = mesh_.connectivity();
  const auto scalpel_at = [&](double s) { return Segment{lerp(from.head, to.head, s), lerp(from.tail, to.tail, s)}; };
  const auto free = [this](ElementId e) { return !refused_.count(e) && !touches_active(e); };
  std::vector<Contact> found;
  for (ElementId e : triangles_near(from, to)) {
    if (!free(e)) continue;
    const Simplex& triangle = c.element(e).simplex;
    const auto o = triangle.oriented_vertices();
    const std::array<Point3, 3> x{deformed(o[0]), deformed(o[1]), deformed(o[2])};
    // An end of the scalpel passing through the triangle (Figure 5.12b).
    for (const auto& [p, q] : {std::pair{from.head, to.head}, std::pair{from.tail, to.tail}})
      if (p != q && !in_plane(p, q, x))
        if (const auto hit = segment_meets_triangle(p, q, x[0], x[1], x[2], p))
          found.push_back({Contact::Way::tip, hit->along, e, triangle, hit->weights});
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      const auto crossing = swept_segment_meets_edge(from.head, from.tail, to.head, to.tail, x[i], x[j]);
      if (!crossing) continue;
      std::array<double, 3> weights{};
      weights[i] = 1 - crossing->on_edge;
      weights[j] = crossing->on_edge;
      const double time = crossing->time;
      const auto later = [&](ElementId t, int corner) {
        return std::any_of(later_fractions.begin(), later_fractions.end(),
                           [&](double f) { return meets_inside(scalpel_at(time + (1 - time) * f), t, corner); });
      };
      const FaceId mate = c.face(c.opposite_face(e, o[k])).mate;
      if (mate == no_id) {
        // Across a boundary edge into its triangle (Figure 5.12a); along it or out of the
        // triangle (leaving an incision's lips) is no entry.
        if (later(e, k)) found.push_back({Contact::Way::boundary_edge, time, e, triangle, weights});
        continue;
      }
      // An exposed edge (Figure 5.12c): a crest that the scalpel meets from outside both its
      // triangles. Each interior edge is looked at from its lower-numbered triangle.
      // "Inside" is off the crossed edge: the scalpel may meet a wing on another of its sides.
      const ElementId other = c.face(mate).element;
      if (other < e || !free(other)) continue;
      const auto p = c.element(other).simplex.oriented_vertices();
      const int far_corner = static_cast<int>(std::find_if(p.begin(), p.begin() + 3, [&](VertexId v) {
                                                return v != o[i] && v != o[j];
                                              }) - p.begin());
      const std::array<Point3, 3> y{deformed(p[0]), deformed(p[1]), deformed(p[2])};
      // Whether the scalpel slides in the plane of triangle t for the whole step (in it at both
      // ends of the step, so throughout), decided on the step's given positions: a blade that
      // only passes through the plane (a level blade rising through a level face) enters across
      // the crest, and whether a blade interpolated at the crossing time lands exactly in the
      // plane is rounding (FMA or not).
      const auto slides = [&](const std::array<Point3, 3>& t) {
        return in_plane(from.head, from.tail, t) && in_plane(to.head, to.tail, t);
      };
      if (slides(x) || slides(y)) continue;
      const Segment before = scalpel_at(time * (1 - 1e-3));
      if (meets_inside(before, e, k) || meets_inside(before, other, far_corner)) continue;
      if (later(e, k) || later(other, far_corner)) found.push_back({Contact::Way::crest, time, e, triangle, weights});
    }
  }
  if (found.empty()) return found;
  // Earliest first; at the same time an edge before a tip (the way with the most to go on).
  std::stable_sort(found.begin(), found.end(), [](const Contact& p, const Contact& q) {
    return p.time != q.time ? p.time < q.time : p.way < q.way;
  });
  const double first = found.front().time;
  std::erase_if(found, [first](const Contact& contact) { return contact.time > first + 1e-9; });
  return found;
}

std::vector<SurfaceCutter::Contact> SurfaceCutter::piercings(const Segment& scalpel) {
  const Connectivity& c = mesh_.connectivity();
  std::vector<Contact> found;
  for (ElementId e : triangles_near(scalpel, scalpel)) {
    if (touches_active(e)) continue;
    const Simplex& triangle = c.element(e).simplex;
    const auto o = triangle.oriented_vertices();
    const Point3 a = deformed(o[0]);
    if (const auto hit = segment_meets_triangle(scalpel.head, scalpel.tail, a, deformed(o[1]), deformed(o[2]), scalpel.head))
      found.push_back({Contact::Way::tip, hit->along, e, triangle, hit->weights});
  }
  std::stable_sort(found.begin(), found.end(), [](const Contact& p, const Contact& q) { return p.time < q.time; });
  return found;
}

}  // namespace snede
