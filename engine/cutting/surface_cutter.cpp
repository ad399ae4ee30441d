#include "cutting/surface_cutter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "cutting/cut_thresholds.hpp"
#include "cutting/incision_star.hpp"
#include "cutting/swept_intersections.hpp"
#include "mesh/deformed_positions.hpp"
#include "topology/collapse_edge.hpp"
#include "topology/dissect.hpp"
#include "topology/flip_edge.hpp"
#include "topology/insert_vertex.hpp"
#include "topology/local_star.hpp"
#include "topology/remove_vertex.hpp"
#include "topology/snap_vertex.hpp"
#include "topology/split_edge.hpp"

namespace snede {
namespace {

// Interior angle at w of triangle (w, a, b).
double angle_at(const Point3& w, const Point3& a, const Point3& b) {
  const Point3 u = minus(a, w), v = minus(b, w);
  return std::atan2(norm(cross(u, v)), dot(u, v));
}

Point3 doubled_normal(const Point3& a, const Point3& b, const Point3& c) { return cross(minus(b, a), minus(c, a)); }

// A new node this close (in barycentric weight) to a side goes on that side.
constexpr double on_side = 1e-6;

// No edit may leave a triangle turned 75° or more from the uncut surface's normal at a corner.
const double facing_cosine = std::cos(75.0 * std::acos(-1.0) / 180);

// Where neighbouring triangles turn by this much or more the surface has a crease (a box's
// edge, a coarse ridge): no flip, removal or move of a node there, which would cut across it
// (a chord through the body); the incision puts its nodes on the path there instead. Figure
// 5.19's bell (392 triangles, neighbours turned by up to 35°) is a smooth surface at this
// angle; the box's edges (90°) and the sharper parts of a coarse organ are creases.
const double crease_cosine = std::cos(45.0 * std::acos(-1.0) / 180);

}  // namespace

SurfaceCutter::SurfaceCutter(Mesh& mesh, DisplacementSource displacement, SurfaceCutterOptions options)
    : mesh_(mesh),
      body_displacement_(std::move(displacement)),
      options_(options),
      watch_(
          mesh.connectivity(), incision_vertices_,
          [this](const Connectivity& c, const IncisionWatch::Fates& fates) { settle(c, fates); },
          [this](const VertexEvent& event) { carry_normal(event); }) {
  watch_.forget_removed_from(ended_);
  if (mesh.cell_dim() != 2 || mesh.space_dim() != 3)
    throw std::invalid_argument("SurfaceCutter: the mesh must be a surface (triangles in 3D), got cell_dim " +
                                std::to_string(mesh.cell_dim()) + " in " + std::to_string(mesh.space_dim()) + "D");
  // §5.4: thresholds as fractions of the mean edge length.
  static_cast<CutThresholds&>(options_) = resolved_thresholds("SurfaceCutter", mesh, options);
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v) && mesh.connectivity().n_vertex_uses(v) > 0) surface_normals_[v] = star_area(v);
  for (const auto& [v, normal] : surface_normals_) {
    const std::vector<Wedge> star = wedges(v);
    if (std::any_of(star.begin(), star.end(), [&](const Wedge& w) { return bends(v, w.y) || bends(v, w.z); }))
      crease_vertices_.insert(v);
  }
}

Point3 SurfaceCutter::reference(VertexId v) const {
  const auto x = mesh_.point(v);
  return {x[0], x[1], x[2]};
}

Point3 SurfaceCutter::deformed(VertexId v) const {
  if (const auto found = moved_.find(v); found != moved_.end()) return found->second;
  return deformed_point(mesh_, displacement_, v);
}

void SurfaceCutter::carry_normal(const VertexEvent& event) {
  if (event.kind == VertexEventKind::removed) {
    forget(event.vertex);  // its id may come back as another vertex
    return;
  }
  if (event.parents.count() == 0) return;  // moved to given coordinates: its normal stays
  Point3 n{0, 0, 0};
  for (std::size_t k = 0; k < event.parents.count(); ++k)
    n = plus_scaled(n, event.parents.weight[k], surface_normal(event.parents.vertex[k]));
  surface_normals_[event.vertex] = n;
  carry_crease(event.vertex, event.parents);
}

void SurfaceCutter::carry_crease(VertexId v, const VertexParents& parents) {
  // A copy of a crease vertex, or a vertex on an edge between two, may lie on the crease; a
  // vertex inside a triangle does not.
  bool on = parents.count() <= 2;
  for (std::size_t k = 0; k < parents.count(); ++k) on = on && crease_vertices_.count(parents.vertex[k]);
  if (on)
    crease_vertices_.insert(v);
  else
    crease_vertices_.erase(v);
}

void SurfaceCutter::forget(VertexId v) {
  moved_.erase(v);
  surface_normals_.erase(v);
  crease_vertices_.erase(v);
}

void SurfaceCutter::settle(const Connectivity& c, const IncisionWatch::Fates& fates) {
  std::vector<VertexId> carried;
  for (auto incision = incisions_.begin(); incision != incisions_.end();) {
    const auto fate = fates.find(incision->active);
    const std::vector<VertexId> heirs = fate == fates.end() ? std::vector<VertexId>{incision->active} : fate->second.heirs;
    // An entry node may be anywhere on the surface; a cut's tip has the two cut edges.
    const auto carries = [&](VertexId v) {
      return std::find(carried.begin(), carried.end(), v) == carried.end() &&
             (incision->entering ? c.n_vertex_uses(v) > 0 : is_incision_tip(mesh_, v, incision_vertices_, fate != fates.end()));
    };
    if (const auto heir = std::find_if(heirs.begin(), heirs.end(), carries); heir != heirs.end()) {
      incision->active = *heir;
      carried.push_back(*heir);
      ++incision;
      continue;
    }
    watch_.lose("SurfaceCutter.move: edits made to the mesh since the last move took an incision's active node " +
                std::to_string(incision->active) + " away (" +
                (fate == fates.end() ? "it is no longer the incision's tip" : fate->second.change) +
                ") and left no vertex that is its tip: that incision ends there, the others go on with the next move");
    incision = incisions_.erase(incision);
  }
  watch_.follow(carried);
}

void SurfaceCutter::follow(VertexId v, const VertexParents& parents) {
  // Watchers interpolate u with the parents' weights, as the reference point is: x follows.
  Point3 x{0, 0, 0};
  for (std::size_t k = 0; k < parents.count(); ++k) {
    const Point3 p = deformed(parents.vertex[k]);
    for (int d = 0; d < 3; ++d) x[d] += parents.weight[k] * p[d];
  }
  moved_[v] = x;
  // The uncut surface's normal there, interpolated as the point is.
  Point3 n{0, 0, 0};
  for (std::size_t k = 0; k < parents.count(); ++k) n = plus_scaled(n, parents.weight[k], surface_normal(parents.vertex[k]));
  surface_normals_[v] = n;
  carry_crease(v, parents);
}

std::vector<Wedge> SurfaceCutter::wedges(VertexId b) const { return star_wedges(mesh_.connectivity(), b); }

bool SurfaceCutter::is_boundary_edge(ElementId triangle, VertexId opposite) const {
  return snede::is_boundary_edge(mesh_.connectivity(), triangle, opposite);
}

Point3 SurfaceCutter::star_area(VertexId v) const {
  Point3 area{0, 0, 0};
  for (const Wedge& w : wedges(v)) area = plus_scaled(area, 1.0, doubled_normal(reference(v), reference(w.y), reference(w.z)));
  return area;
}

Point3 SurfaceCutter::surface_normal(VertexId v) const {
  if (const auto found = surface_normals_.find(v); found != surface_normals_.end()) return found->second;
  return star_area(v);  // a vertex another edit made since: its star's vector area
}

bool SurfaceCutter::faces_surface(const Point3& normal, VertexId a, VertexId b, VertexId c) const {
  // At every corner: a triangle across a sharp crease must not lean away from either side.
  for (VertexId v : {a, b, c})
    if (const Point3 surface = surface_normal(v); !(dot(normal, surface) > facing_cosine * norm(normal) * norm(surface)))
      return false;
  return true;
}

bool SurfaceCutter::keeps_facing(VertexId v, const Point3& x, VertexId merging_into, Wedge* refused_by) const {
  // The edits' own checks refuse only normals turned by 90° or more; on a curved surface
  // repeated turns short of that can fold it, so the cutter asks each edit for less than 60°,
  // and every new triangle to face the way the uncut surface does where it is (the turns of
  // successive edits add up: a star triangle that v's moves squeeze into a sliver swings by
  // tens of degrees each time).
  for (const Wedge& w : wedges(v)) {
    if (w.y == merging_into || w.z == merging_into) continue;  // collapsed away
    const Point3 y = reference(w.y), z = reference(w.z);
    const Point3 before = doubled_normal(reference(v), y, z), after = doubled_normal(x, y, z);
    if (!(dot(before, after) > 0.5 * std::sqrt(dot(before, before) * dot(after, after))) ||
        !faces_surface(after, v, w.y, w.z)) {
      if (refused_by) *refused_by = w;
      return false;
    }
  }
  return true;
}

bool SurfaceCutter::is_crease(VertexId p, VertexId q) const {
  return crease_vertices_.count(p) && crease_vertices_.count(q) && bends(p, q);
}

bool SurfaceCutter::bends(VertexId p, VertexId q) const {
  const Connectivity& c = mesh_.connectivity();
  const std::vector<ElementId> wings = elements_with_edge(c, p, q);
  if (wings.size() != 2) return false;
  std::array<Point3, 2> n;
  const double length = distance(reference(p), reference(q));
  for (int k = 0; k < 2; ++k) {
    const auto t = c.element(wings[k]).simplex.oriented_vertices();
    n[k] = doubled_normal(reference(t[0]), reference(t[1]), reference(t[2]));
    // A triangle squeezed flat (an active node closing in on a vertex) has no direction to bend.
    if (norm(n[k]) <= 1e-6 * length * length) return false;
  }
  return !(dot(n[0], n[1]) > crease_cosine * norm(n[0]) * norm(n[1]));
}

bool SurfaceCutter::on_crease(VertexId v) const {
  if (!crease_vertices_.count(v)) return false;
  const std::vector<Wedge> star = wedges(v);
  return std::any_of(star.begin(), star.end(), [&](const Wedge& w) { return is_crease(v, w.y) || is_crease(v, w.z); });
}

bool SurfaceCutter::on_boundary(VertexId v) const { return touches_boundary(mesh_.connectivity(), v); }

bool SurfaceCutter::is_active(VertexId v) const {
  return std::any_of(incisions_.begin(), incisions_.end(), [v](const Incision& i) { return i.active == v; });
}

SurfaceCutter::Incision* SurfaceCutter::incision_at(VertexId active) {
  for (Incision& i : incisions_)
    if (i.active == active) return &i;
  return nullptr;
}

std::vector<VertexId> SurfaceCutter::active_nodes() const {
  std::vector<VertexId> nodes;
  for (const Incision& i : incisions_) nodes.push_back(i.active);
  return nodes;
}

std::vector<VertexId> SurfaceCutter::active_neighbours(VertexId v, VertexId except) const {
  std::vector<VertexId> found;
  for (const Wedge& w : wedges(v))
    for (VertexId u : {w.y, w.z})
      if (u != except && is_active(u) && std::find(found.begin(), found.end(), u) == found.end()) found.push_back(u);
  return found;
}

bool SurfaceCutter::touches_active(ElementId triangle, VertexId except) const {
  for (VertexId v : mesh_.connectivity().element(triangle).simplex.vertices())
    if (v != except && is_active(v)) return true;
  return false;
}

Point3 SurfaceCutter::reference_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights) const {
  const Point3 B = reference(b), Y = reference(w.y), Z = reference(w.z);
  Point3 x{};
  for (int d = 0; d < 3; ++d) x[d] = weights[0] * B[d] + weights[1] * Y[d] + weights[2] * Z[d];
  return x;
}

Point3 SurfaceCutter::deformed_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights) const {
  const Point3 B = deformed(b), Y = deformed(w.y), Z = deformed(w.z);
  Point3 x{};
  for (int d = 0; d < 3; ++d) x[d] = weights[0] * B[d] + weights[1] * Y[d] + weights[2] * Z[d];
  return x;
}

std::vector<SurfaceCutter::StarHit> SurfaceCutter::hits_in_star(VertexId b, const Segment& scalpel) const {
  std::vector<std::pair<double, StarHit>> found;
  const Point3 xb = deformed(b);
  for (const Wedge& w : wedges(b)) {
    const auto hit = segment_meets_triangle(scalpel.head, scalpel.tail, xb, deformed(w.y), deformed(w.z), xb);
    if (hit) found.push_back({distance(deformed_at(w, b, hit->weights), xb), StarHit{w, hit->weights}});
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
  std::vector<StarHit> hits;
  for (const auto& [r, hit] : found) hits.push_back(hit);
  return hits;
}

SurfaceCutter::Segment SurfaceCutter::through(const Segment& scalpel, const Point3& x) {
  const Point3 along = minus(scalpel.tail, scalpel.head);
  const Point3 shift = minus(x, plus_scaled(scalpel.head, dot(minus(x, scalpel.head), along) / dot(along, along), along));
  return {plus_scaled(scalpel.head, 1.0, shift), plus_scaled(scalpel.tail, 1.0, shift)};
}

std::optional<SurfaceCutter::LinkCrossing> SurfaceCutter::first_link_crossing(VertexId b, const Segment& from,
                                                                             const Segment& to) const {
  std::optional<LinkCrossing> first;
  for (const Wedge& w : wedges(b)) {
    const auto crossing = swept_segment_meets_edge(from.head, from.tail, to.head, to.tail, deformed(w.y), deformed(w.z));
    if (crossing && (!first || crossing->time < first->time)) first = LinkCrossing{w, crossing->time, crossing->on_edge};
  }
  return first;
}

double SurfaceCutter::step_limit(VertexId b, const Segment& scalpel) const {
  double limit = std::numeric_limits<double>::infinity();
  for (const Wedge& w : wedges(b)) limit = std::min(limit, line_distance(scalpel.head, scalpel.tail, deformed(w.y), deformed(w.z)));
  // §5.3.1: a scalpel nearly parallel to the surface moves its hit far for a small move of its
  // ends; d_max keeps the hit within the star. The floor only bounds the number of steps; at
  // ε_edge/4 it let the hit jump across the star in one step on a coarse surface, and the node
  // was left behind (below ε_edge/8 the bell's cap, cut by a tangent scalpel, gets slivers).
  return std::max(limit, options_.eps_edge / 8);
}

std::vector<ElementId> SurfaceCutter::triangles_near(const Segment& from, const Segment& to) {
  // The grid is built once per move (or when another edit changed the mesh since); the
  // triangles this move's edits made are around the vertices it touched or moved, and join
  // the candidates as they are, so that a step costs no rebuild.
  const Connectivity& c = mesh_.connectivity();
  if (rebuild_grid_) {
    grid_.build(mesh_, [this](VertexId v) { return deformed(v); });
    grid_revision_ = c.revision();
    rebuild_grid_ = false;
  }
  std::vector<ElementId> found;
  for (ElementId e : grid_.near_sweep(from.head, from.tail, to.head, to.tail))
    if (c.is_element(e)) found.push_back(e);
  if (c.revision() != *grid_revision_) {
    std::vector<VertexId> edited = touched_;
    for (const auto& [v, x] : moved_) edited.push_back(v);
    for (VertexId v : edited)
      if (mesh_.is_vertex(v))
        for (ElementId e : local_star(c, v).elements) found.push_back(e);
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
  }
  return found;
}

bool SurfaceCutter::meets_ring(VertexId a, const Segment& scalpel) const {
  const Connectivity& c = mesh_.connectivity();
  for (const Wedge& w : wedges(a))
    for (VertexId v : {a, w.y, w.z})
      for (ElementId e : local_star(c, v).elements) {
        const Simplex& t = c.element(e).simplex;
        const Point3 p = deformed(t.vertex(0));
        if (segment_meets_triangle(scalpel.head, scalpel.tail, p, deformed(t.vertex(1)), deformed(t.vertex(2)), p)) return true;
      }
  return false;
}

PlanarCutResult SurfaceCutter::move(std::span<const double> segment) {
  if (segment.size() != 6)
    throw std::invalid_argument("SurfaceCutter.move: the scalpel is a segment, 2 ends of 3 coordinates; got " +
                                std::to_string(segment.size()) + " numbers");
  require_finite_points(segment.data(), segment.size(), 3, "SurfaceCutter.move", "segment");
  const Segment now{{segment[0], segment[1], segment[2]}, {segment[3], segment[4], segment[5]}};
  if (now.head == now.tail) throw std::invalid_argument("SurfaceCutter.move: the scalpel's two ends coincide (segment)");
  CutterMove this_move(watch_, mesh_);
  PlanarCutResult& report = this_move.report();
  displacement_.clear();
  moved_.clear();
  if (body_displacement_) {
    const DisplacementRead u = body_displacement_();
    displacement_.assign(u.values.begin(), u.values.end());
  }
  // Deformed positions or the mesh may have changed since the grid was built.
  rebuild_grid_ = rebuild_grid_ || body_displacement_ || grid_revision_ != mesh_.connectivity().revision();
  touched_.clear();
  refused_.clear();
  // §5.2.2: where incisions ended stays forbidden until the scalpel has moved 2 ε_exit away
  // (else a scalpel still at an exit enters again through the lips it just made).
  std::erase_if(ended_, [&](VertexId v) { return segment_point_distance(now.head, now.tail, deformed(v)) > 2 * options_.eps_exit; });
  for (VertexId v : ended_)
    for (ElementId e : local_star(mesh_.connectivity(), v).elements) refused_.insert(e);
  {
    // A body hears of the move's edits at once, when it is over.
    ChangeBatch batch(mesh_.connectivity());
    if (scalpel_) {
      sweep(*scalpel_, now, report);
    } else {
      // Placed through the surface: it enters where it pierces it.
      for (const Contact& contact : piercings(now)) enter(contact, report);
    }
    scalpel_ = now;
    for (const Incision& i : incisions_) touched_.push_back(i.active);
    legalize(report);
  }
  watch_.follow(active_nodes());
  return this_move.finished();
}

void SurfaceCutter::lift() {
  incisions_.clear();
  ended_.clear();
  scalpel_.reset();
  watch_.follow({});
}

void SurfaceCutter::sweep(const Segment& from, const Segment& to, PlanarCutResult& report) {
  const double movement = std::max(distance(from.head, to.head), distance(from.tail, to.tail));
  const auto at = [&](double s) { return Segment{lerp(from.head, to.head, s), lerp(from.tail, to.tail, s)}; };
  Segment current = from;
  double done = 0;
  // Figure 5.11: steps no longer than d_max near every active node; at most 256 of them.
  for (int step = 0; step < 256 && done < 1; ++step) {
    double next = 1;
    if (movement > 0 && step < 255)
      for (const Incision& i : incisions_) next = std::min(next, done + step_limit(i.active, current) / movement);
    Segment target = at(next);
    // An entry node waits for the scalpel to move away from it; halving the step keeps the
    // places where it meets the node's triangles in them, so that none is lost on the way
    // (at a crest they move far faster than the scalpel).
    for (int halving = 0; halving < 20 && loses_place(current, target); ++halving) target = at(next = (done + next) / 2);
    // The step ends where the scalpel first touches the surface somewhere new (Figure 5.12).
    const std::vector<Contact> contacts = first_contacts(current, target);
    if (!contacts.empty()) {
      next = done + (next - done) * contacts.front().time;
      target = at(next);
    }
    follow_scalpel(current, target, report);
    for (const Contact& contact : contacts)
      if (!enter(contact, report)) refused_.insert(contact.element);
    current = target;
    done = next;
  }
}

std::size_t SurfaceCutter::places_in_star(VertexId a, const Segment& scalpel) const {
  std::vector<Point3> places;
  for (const StarHit& hit : hits_in_star(a, scalpel)) {
    const Point3 x = reference_at(hit.wedge, a, hit.weights);
    if (std::none_of(places.begin(), places.end(), [&](const Point3& p) { return distance(p, x) <= 1e-9 * options_.eps_edge; }))
      places.push_back(x);
  }
  return places.size();
}

bool SurfaceCutter::loses_place(const Segment& from, const Segment& to) const {
  return std::any_of(incisions_.begin(), incisions_.end(), [&](const Incision& i) {
    if (!i.entering) return false;
    // A crest is met on both sides at once: two places from the start.
    const std::size_t before = std::max<std::size_t>(places_in_star(i.active, from), i.branching ? 2 : 0);
    return places_in_star(i.active, to) < before;
  });
}

void SurfaceCutter::follow_scalpel(const Segment& from, const Segment& to, PlanarCutResult& report) {
  for (VertexId a : active_nodes()) {
    const Incision* incision = incision_at(a);  // another incision may have ended this one
    if (!incision) continue;
    if (incision->entering)
      begin_incision(a, to, report);
    else
      advance(a, from, to, report);
  }
}

VertexId SurfaceCutter::free_vertex_near(const Point3& at, std::span<const VertexId> candidates, double radius) const {
  VertexId best = -1;
  double nearest = radius;
  for (VertexId v : candidates)
    if (const double r = distance(at, reference(v)); r <= nearest && !is_active(v) && active_neighbours(v, -1).empty())
      nearest = r, best = v;
  return best;
}

bool SurfaceCutter::enter(const Contact& contact, PlanarCutResult& report) {
  const Connectivity& c = mesh_.connectivity();
  // Earlier edits of this step may have replaced the triangle (and its id been reused).
  if (!c.is_element(contact.element) || c.element(contact.element).simplex != contact.triangle) return false;
  if (touches_active(contact.element)) return false;
  const auto corners = contact.triangle.oriented_vertices();
  const Wedge w{contact.element, corners[1], corners[2]};
  const Point3 at = reference_at(w, corners[0], contact.weights);
  VertexId entry = -1;
  if (contact.way == Contact::Way::tip) {
    entry = free_vertex_near(at, std::span<const VertexId>(corners.data(), 3), options_.eps_entry);
    if (entry < 0) entry = insert_at(w, corners[0], contact.weights, report);
  } else {
    // On the edge whose opposite corner has weight 0.
    const int opposite = static_cast<int>(std::min_element(contact.weights.begin(), contact.weights.end()) -
                                          contact.weights.begin());
    const VertexId y = corners[(opposite + 1) % 3], z = corners[(opposite + 2) % 3];
    if (contact.way == Contact::Way::crest) {
      for (ElementId e : elements_with_edge(c, y, z))
        if (touches_active(e)) return false;
    }
    const std::array<VertexId, 2> ends{y, z};
    entry = free_vertex_near(at, ends, options_.eps_entry);
    const double mu = contact.weights[(opposite + 2) % 3];
    if (entry < 0 && (entry = split(y, z, mu)) >= 0) {
      ++report.nodes_inserted;
      if (incision_vertices_.count(y) && incision_vertices_.count(z)) incision_vertices_.insert(entry);  // on a lip
    }
  }
  if (entry < 0) return false;
  incisions_.push_back({entry, true, contact.way == Contact::Way::crest});
  touched_.push_back(entry);
  ++report.entries;
  return true;
}

void SurfaceCutter::begin_incision(VertexId a, const Segment& scalpel, PlanarCutResult& report) {
  const std::vector<StarHit> hits = hits_in_star(a, scalpel);
  if (hits.empty()) {
    if (!meets_ring(a, scalpel)) std::erase_if(incisions_, [a](const Incision& i) { return i.active == a; });  // withdrawn
    return;
  }
  if (const double apart = branch_distance(a); branches(a, scalpel, apart).size() >= 2) {
    branch(a, scalpel, apart, report);
    return;
  }
  const StarHit& hit = hits.front();
  if (distance(reference_at(hit.wedge, a, hit.weights), reference(a)) <= options_.eps_entry) return;
  const VertexId b = insert_at(hit.wedge, a, hit.weights, report);
  if (b < 0 || !has_edge(mesh_.connectivity(), a, b)) return;
  open_from(a, {b}, report);
}

void SurfaceCutter::open_from(VertexId a, const std::vector<VertexId>& ends, PlanarCutResult& report) {
  std::vector<std::array<VertexId, 2>> slit;
  if (ends.size() == 1 && !on_boundary(a)) {
    // An interior edge does not open (both ends' stars stay whole): split it, so that the
    // slit a–m–b opens at m.
    const VertexId m = split(a, ends.front(), 0.5);
    if (m < 0) return;
    ++report.nodes_inserted;
    slit = {{a, m}, {m, ends.front()}};
    incision_vertices_.insert(m);
  } else {
    for (VertexId b : ends) slit.push_back({a, b});
  }
  for (VertexId v : dissect_edges(slit)) incision_vertices_.insert(v), touched_.push_back(v);
  incision_vertices_.insert(a);
  touched_.push_back(a);
  std::erase_if(incisions_, [a](const Incision& i) { return i.active == a; });
  for (VertexId b : ends) {
    incision_vertices_.insert(b);
    touched_.push_back(b);
    incisions_.push_back({b, false, false});
  }
  for (VertexId b : ends) remesh_around(b, report);
}

double SurfaceCutter::branch_distance(VertexId a) {
  // A crest entry branches as soon as the scalpel meets both sides apart from the entry node:
  // one side may be steep, its hit leaving the star before the other has gone ε_entry. The
  // short edges this leaves go as the scalpel moves on (§5.3.2).
  const Incision* incision = incision_at(a);
  return incision && incision->branching ? 1e-2 * options_.eps_edge : options_.eps_entry;
}

std::vector<SurfaceCutter::StarHit> SurfaceCutter::branches(VertexId a, const Segment& scalpel, double apart) const {
  std::vector<StarHit> far;
  std::vector<Point3> places;
  for (const StarHit& hit : hits_in_star(a, scalpel)) {
    const Point3 x = reference_at(hit.wedge, a, hit.weights);
    if (distance(x, reference(a)) <= apart) return {};  // the scalpel is still at a
    if (std::all_of(places.begin(), places.end(), [&](const Point3& p) { return distance(p, x) > apart; }))
      far.push_back(hit), places.push_back(x);
  }
  return far.size() >= 2 ? far : std::vector<StarHit>{};
}

void SurfaceCutter::branch(VertexId a, const Segment& scalpel, double apart, PlanarCutResult& report) {
  // Figure 5.14: a node at each place, inserted in turn (each into triangles the earlier
  // ones left alone), then the edges from a to them dissected.
  const Connectivity& c = mesh_.connectivity();
  std::vector<Point3> places;
  for (const StarHit& hit : branches(a, scalpel, apart)) places.push_back(reference_at(hit.wedge, a, hit.weights));
  std::vector<VertexId> made;
  const auto keeps_apart = [&](const StarHit& hit) {
    // The triangles the new node will be in: the hit's, and across the side it is on.
    std::vector<ElementId> hosts{hit.wedge.element};
    const std::array<VertexId, 3> corners{a, hit.wedge.y, hit.wedge.z};
    const int smallest = static_cast<int>(std::min_element(hit.weights.begin(), hit.weights.end()) - hit.weights.begin());
    if (hit.weights[smallest] <= on_side)
      hosts = elements_with_edge(c, corners[(smallest + 1) % 3], corners[(smallest + 2) % 3]);
    return std::none_of(hosts.begin(), hosts.end(), [&](ElementId e) {
      const Simplex& t = c.element(e).simplex;
      return std::any_of(made.begin(), made.end(), [&](VertexId m) { return t.contains(m); });
    });
  };
  for (const Point3& place : places) {
    for (const StarHit& hit : hits_in_star(a, scalpel)) {
      if (!keeps_apart(hit) || distance(reference_at(hit.wedge, a, hit.weights), place) > apart) continue;
      if (const VertexId m = insert_at(hit.wedge, a, hit.weights, report); m >= 0) made.push_back(m);
      break;
    }
  }
  if (made.empty()) return;
  if (made.size() >= 2) ++report.branches;
  open_from(a, made, report);
}

VertexId SurfaceCutter::insert_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights,
                                  PlanarCutResult& report) {
  const std::array<VertexId, 3> corners{b, w.y, w.z};
  const int smallest = static_cast<int>(std::min_element(weights.begin(), weights.end()) - weights.begin());
  VertexId made = -1;
  if (weights[smallest] > on_side) {
    const auto oriented = mesh_.connectivity().element(w.element).simplex.oriented_vertices();
    std::array<double, 3> in_order{};
    for (int k = 0; k < 3; ++k) in_order[k] = weights[std::find(corners.begin(), corners.end(), oriented[k]) - corners.begin()];
    if (const EditResult inserted = insert_vertex(mesh_, w.element, in_order); inserted.done) {
      made = inserted.vertex;
      follow(made, VertexParents::barycentric(std::span<const VertexId>(oriented.data(), 3), in_order));
    }
  }
  if (made < 0) {  // on or too near a side: split that side, unless its other triangle has another active node
    const VertexId s = corners[(smallest + 1) % 3], t = corners[(smallest + 2) % 3];
    for (ElementId e : elements_with_edge(mesh_.connectivity(), s, t))
      if (touches_active(e, b)) return -1;
    const double ws = weights[(smallest + 1) % 3], wt = weights[(smallest + 2) % 3];
    made = split(s, t, std::clamp(wt / (ws + wt), 0.05, 0.95));
  }
  if (made >= 0) ++report.nodes_inserted;
  return made;
}

VertexId SurfaceCutter::split(VertexId a, VertexId b, double t) {
  const EditResult result = split_edge(mesh_, a, b, t);
  if (!result.done) return -1;
  follow(result.vertex, VertexParents::on_edge(a, b, t));
  return result.vertex;
}

void SurfaceCutter::advance(VertexId b, Segment from, const Segment& to, PlanarCutResult& report) {
  for (int attempt = 0; attempt < 64 && incision_at(b); ++attempt) {
    const std::vector<StarHit> hits = hits_in_star(b, to);
    if (!hits.empty()) {
      if (branches(b, to, options_.eps_entry).size() >= 2) {
        branch(b, to, options_.eps_entry, report);
        return;
      }
      if (on_crease(b)) {
        // Moving b would take the crease along: the incision goes on from a node at the hit.
        if (distance(reference_at(hits.front().wedge, b, hits.front().weights), reference(b)) < crease_step()) return;
        const VertexId next = cut_to_hit(b, hits.front(), report);
        if (next < 0) ++report.stuck;
        else split_incision(next, report);
        return;
      }
      std::optional<Wedge> blocking;
      if (!move_active_to(b, hits.front().wedge, hits.front().weights, &blocking)) {
        // A star triangle would fold over on the whole way (the 2D cutter's triangle that
        // the way inverts): its link edge is cleared away and the hit looked for again. One
        // the node leaves behind (dragged along from a crease it crossed) is taken out of the
        // star by flipping a spoke instead: "the active triangles are subjected to flipping"
        // (§5.3.1).
        if (blocking && (clear_link_edge(b, blocking->y, blocking->z, report) || flip(b, blocking->y, report) ||
                         flip(b, blocking->z, report)))
          continue;
        ++report.stuck;
      }
      remesh_around(b, report);
      split_incision(b, report);
      return;
    }
    // §5.3.1: the scalpel has left the active triangles across the edge it swept first. The
    // thesis's node is at the scalpel when a step begins; one a refused move left behind is
    // swept to from where it is (the scalpel moved over to it), or it would stay there for good.
    std::optional<LinkCrossing> crossing = first_link_crossing(b, from, to);
    if (!crossing) crossing = first_link_crossing(b, through(from, deformed(b)), to);
    if (!crossing) {
      if (meets_ring(b, to)) ++report.stuck;
      return;
    }
    const Wedge& w = crossing->wedge;
    // An edge not to be flipped ends the incision there (Figure 5.13): a boundary edge (the
    // exit), or one with another active node across it.
    const std::vector<ElementId> wings = elements_with_edge(mesh_.connectivity(), w.y, w.z);
    const bool across_active = std::any_of(wings.begin(), wings.end(), [&](ElementId e) {
      return e != w.element && touches_active(e);
    });
    if (is_boundary_edge(w.element, b) || across_active) {
      move_active_to(b, w, {0.4, 0.6 * (1 - crossing->mu), 0.6 * crossing->mu});
      end_at_edge(b, w.y, w.z, crossing->mu, report);
      return;
    }
    if (on_crease(b) || is_crease(w.y, w.z)) {
      // Neither b nor the edge may move across the crease: a node where the path crosses it.
      const VertexId next = cut_to_edge(b, w.y, w.z, crossing->mu, report);
      if (next < 0) {
        ++report.stuck;
        return;
      }
      // The new node is where the scalpel crossed: it sweeps on from there.
      from = {lerp(from.head, to.head, crossing->time), lerp(from.tail, to.tail, crossing->time)};
      b = next;
      continue;
    }
    move_active_to(b, w, {0.4, 0.6 * (1 - crossing->mu), 0.6 * crossing->mu});
    if (!clear_link_edge(b, w.y, w.z, report)) {
      ++report.stuck;
      return;
    }
  }
}

VertexId SurfaceCutter::cut_to_edge(VertexId b, VertexId y, VertexId z, double mu, PlanarCutResult& report) {
  const Point3 at = lerp(reference(y), reference(z), mu);
  // An end of the edge near the crossing is the node, if it can carry the incision.
  const auto usable = [&](VertexId v) {
    return distance(at, reference(v)) < crease_step() && !incision_vertices_.count(v) && !on_boundary(v) &&
           active_neighbours(v, b).empty();
  };
  VertexId next = usable(y) ? y : usable(z) ? z : -1;
  if (next < 0) {
    // Not onto an end that cannot carry it (as insert_at keeps a side's new node off its ends).
    if ((next = split(y, z, std::clamp(mu, 0.05, 0.95))) < 0) return -1;
    ++report.nodes_inserted;
  }
  if (distance(reference(b), reference(next)) < crease_step() && keeps_facing(b, reference(next), next) &&
      collapse_edge(mesh_, next, b, 0).done) {
    // b this close to the crease: its incision goes on from there, without a short cut edge.
    ++report.edges_contracted;
    incision_at(b)->active = next;
    incision_vertices_.erase(b);
    incision_vertices_.insert(next);
    forget(b);
    touched_.push_back(next);
    return next;
  }
  open_from(b, {next}, report);
  return incision_at(next) ? next : -1;
}

VertexId SurfaceCutter::cut_to_hit(VertexId b, const StarHit& hit, PlanarCutResult& report) {
  const VertexId next = insert_at(hit.wedge, b, hit.weights, report);
  if (next < 0 || !has_edge(mesh_.connectivity(), b, next)) return -1;
  open_from(b, {next}, report);
  return incision_at(next) ? next : -1;
}

bool SurfaceCutter::clear_link_edge(VertexId b, VertexId y, VertexId z, PlanarCutResult& report) {
  if (flip(y, z, report)) return true;
  // A flip refused (Figure 5.9, or a fold): remove the nearer interior end instead.
  VertexId first = y, second = z;
  if (distance(reference(second), reference(b)) < distance(reference(first), reference(b))) std::swap(first, second);
  for (VertexId v : {first, second})
    if (!incision_vertices_.count(v) && !on_boundary(v) && remove_node(v, report)) return true;
  return false;
}

bool SurfaceCutter::move_active_to(VertexId b, const Wedge& w, std::array<double, 3> weights,
                                   std::optional<Wedge>* blocking) {
  if (on_crease(b)) return false;  // it would take the crease along, off the surface
  const std::array<VertexId, 3> parents{b, w.y, w.z};
  // Part of the way when the whole way would flatten or fold a triangle of the star.
  for (double fraction : {1.0, 0.75, 0.5, 0.25}) {
    std::array<double, 3> part{1 - fraction + fraction * weights[0], fraction * weights[1], fraction * weights[2]};
    const double sum = part[0] + part[1] + part[2];
    for (double& x : part) x /= sum;
    const VertexParents target = VertexParents::barycentric(parents, part);
    const Point3 before = deformed(b);
    Wedge refused_by{};
    if (!keeps_facing(b, reference_at(w, b, part), -1, &refused_by)) {
      if (blocking && fraction == 1.0) *blocking = refused_by;
      continue;
    }
    if (snap_vertex(mesh_, b, target).done) {
      moved_[b] = before;  // follow() reads the active node's old position as a parent
      follow(b, target);
      return fraction == 1.0;
    }
  }
  return false;
}

bool SurfaceCutter::flip(VertexId p, VertexId q, PlanarCutResult& report) {
  const Connectivity& c = mesh_.connectivity();
  const std::vector<ElementId> wings = elements_with_edge(c, p, q);
  if (wings.size() != 2 || is_crease(p, q)) return false;
  std::vector<VertexId> quad{p, q};
  std::vector<Point3> old_normals;
  for (ElementId e : wings) {
    const auto t = c.element(e).simplex.oriented_vertices();
    old_normals.push_back(doubled_normal(reference(t[0]), reference(t[1]), reference(t[2])));
    quad.push_back(third_vertex(c.element(e).simplex, p, q));
  }
  // §5.3.2: no triangle may touch two active nodes.
  const auto actives = [this](std::initializer_list<VertexId> t) { return std::count_if(t.begin(), t.end(), [this](VertexId v) { return is_active(v); }); };
  VertexId left = quad[2], right = quad[3];
  if (actives({p, left, right}) > 1 || actives({q, left, right}) > 1) return false;
  // The new triangles (p, d, c) and (q, c, d), (p, q, c) being the old left one, must turn
  // by less than 60° from both old ones (as keeps_facing asks of moves).
  if (c.element(wings[0]).simplex != Simplex(1, {p, q, left})) std::swap(left, right);
  for (const auto& [x, y, z] : {std::array<VertexId, 3>{p, right, left}, std::array<VertexId, 3>{q, left, right}}) {
    const Point3 n = doubled_normal(reference(x), reference(y), reference(z));
    if (!faces_surface(n, x, y, z)) return false;
    for (const Point3& old : old_normals)
      if (!(dot(n, old) > 0.5 * std::sqrt(dot(n, n) * dot(old, old)))) return false;
  }
  if (!flip_edge(mesh_, p, q).done) return false;
  ++report.flips;
  touched_.insert(touched_.end(), quad.begin(), quad.end());
  return true;
}

bool SurfaceCutter::remove_node(VertexId v, PlanarCutResult& report) {
  // §5.3.2: active nodes stay, and so do the nodes that separate two of them.
  if (is_active(v) || active_neighbours(v, -1).size() > 1 || on_crease(v)) return false;
  std::vector<VertexId> link;
  for (const Wedge& w : wedges(v)) link.insert(link.end(), {w.y, w.z});
  // The new triangles must face the way the surface does, as those of moves and flips.
  const auto faces = [this](const Simplex& t) {
    const auto o = t.oriented_vertices();
    return faces_surface(doubled_normal(reference(o[0]), reference(o[1]), reference(o[2])), o[0], o[1], o[2]);
  };
  if (!remove_vertex_by_flips(mesh_, v, faces).done) return false;
  ++report.nodes_removed;
  forget(v);
  touched_.insert(touched_.end(), link.begin(), link.end());
  return true;
}

void SurfaceCutter::remesh_around(VertexId b, PlanarCutResult& report) {
  if (!mesh_.is_vertex(b) || !incision_at(b)) return;
  // §5.3.1: the active triangles' edges to the unfolded Delaunay criterion.
  flip_star_towards_delaunay(mesh_, b, [&](VertexId p, VertexId q) { return flip(p, q, report); });
  // Interior nodes closer than ε_edge to the active node go (§5.2.2); one that separates b
  // from another active node is where both incisions end (Figure 5.13).
  for (int round = 0; round < 16; ++round) {
    const Point3 x = reference(b);
    VertexId closest = -1;
    double nearest = options_.eps_edge;
    for (const Wedge& w : wedges(b))
      for (VertexId v : {w.y, w.z})
        if (const double r = distance(reference(v), x); r < nearest && !incision_vertices_.count(v) && !on_boundary(v))
          nearest = r, closest = v;
    if (closest < 0) break;
    if (!active_neighbours(closest, b).empty()) {
      end_at_node(b, closest, report);
      return;
    }
    if (!remove_node(closest, report)) break;
  }
}

void SurfaceCutter::split_incision(VertexId b, PlanarCutResult& report) {
  if (!incision_at(b)) return;
  // The cut edges: boundary edges (b, c1) of wedge (b, c1, o1) and (b, c2) of (b, o2, c2).
  std::optional<Wedge> out, in;
  for (const Wedge& w : wedges(b)) {
    if (is_boundary_edge(w.element, w.z)) out = w;
    if (is_boundary_edge(w.element, w.y)) in = w;
  }
  if (!out || !in || out->element == in->element) return;
  const VertexId c1 = out->y, o1 = out->z, o2 = in->y, c2 = in->z;
  if (o1 == o2 || !incision_vertices_.count(c1) || !incision_vertices_.count(c2)) return;
  const Point3 pb = reference(b), p1 = reference(o1), p2 = reference(o2);
  const Point3 pc = lerp(reference(c1), reference(c2), 0.5);
  // Figure 5.5 unfolded: the cut edges seen as one edge b–c fail the empty-circle test when
  // the angles facing them add up to more than π.
  if (angle_at(p1, pb, reference(c1)) + angle_at(p2, pb, reference(c2)) <= std::acos(-1.0) * (1 + 1e-12)) return;
  // Unfold o1 and o2 to either side of b–c: the line between them crosses it at s.
  const double length = distance(pb, pc);
  if (length == 0) return;
  const Point3 along = minus(pc, pb);
  const auto unfolded = [&](const Point3& o) {
    const double x = dot(minus(o, pb), along) / length;
    return std::pair{x, std::sqrt(std::max(dot(minus(o, pb), minus(o, pb)) - x * x, 0.0))};
  };
  const auto [x1, h1] = unfolded(p1);
  const auto [x2, h2] = unfolded(p2);
  if (h1 + h2 == 0) return;
  const double s = (x1 + (x2 - x1) * h1 / (h1 + h2)) / length;
  if (!(s * length > 0.25 * options_.eps_edge && (1 - s) * length > 0.25 * options_.eps_edge)) return;
  const Point3 at = lerp(pb, pc, s);
  // A new node within ε_edge/2 of an opposite node would leave a sliver: that node goes if it
  // is interior, and the next move looks again.
  const VertexId nearer = distance(at, p1) < distance(at, p2) ? o1 : o2;
  if (distance(at, reference(nearer)) < 0.5 * options_.eps_edge) {
    if (!incision_vertices_.count(nearer) && !on_boundary(nearer) && remove_node(nearer, report)) remesh_around(b, report);
    return;
  }
  const VertexId first = split(b, c1, s);
  if (first < 0) return;
  const VertexId second = split(b, c2, s);
  if (second < 0) {  // keep the lips alike: undo the first
    collapse_edge(mesh_, c1, first, 0);
    moved_.erase(first);
    return;
  }
  incision_vertices_.insert(first);
  incision_vertices_.insert(second);
  touched_.insert(touched_.end(), {first, second});
  report.nodes_inserted += 2;
  ++report.incision_splits;
  remesh_around(b, report);
}

std::vector<VertexId> SurfaceCutter::dissect_edges(const std::vector<std::array<VertexId, 2>>& edges) {
  Connectivity& c = mesh_.connectivity();
  std::vector<FaceId> faces;
  for (const auto& [a, b] : edges) {
    // A missing edge, or one already on the boundary, has nothing to open.
    const std::vector<ElementId> wings = elements_with_edge(c, a, b);
    if (wings.size() == 2) faces.push_back(c.opposite_face(wings.front(), third_vertex(c.element(wings.front()).simplex, a, b)));
  }
  if (faces.empty()) return {};
  const std::vector<SplitVertex> split =
      dissect(c, faces, [this](VertexId v) { return mesh_.add_vertex(VertexParents::copy_of(v)); });
  std::vector<VertexId> copies;
  for (const SplitVertex& s : split) {
    follow(s.copy, VertexParents::copy_of(s.original));
    copies.push_back(s.copy);
  }
  return copies;
}

void SurfaceCutter::end_at_edge(VertexId b, VertexId y, VertexId z, double mu, PlanarCutResult& report) {
  const bool exit = elements_with_edge(mesh_.connectivity(), y, z).size() == 1;
  const Point3 py = reference(y), pz = reference(z), at = lerp(py, pz, mu);
  VertexId w = -1;
  if (distance(at, py) <= options_.eps_exit)
    w = y;
  else if (distance(at, pz) <= options_.eps_exit)
    w = z;
  else if ((w = split(y, z, mu)) >= 0)
    ++report.nodes_inserted;
  else
    w = distance(at, py) < distance(at, pz) ? y : z;
  if (!exit) {
    end_at_node(b, w, report);
    return;
  }
  const std::vector<VertexId> copies = join_at(w, {b});
  if (copies.empty()) return;
  ++report.exits;
  // Figure 5.7: the short edges the exit leaves are contracted, each copy of b into its w.
  std::vector<VertexId> tips{b}, exit_ends{w};
  for (VertexId v : copies) (mesh_.parents(v).vertex.front() == b ? tips : exit_ends).push_back(v);
  for (VertexId tip : tips)
    for (VertexId end : exit_ends)
      if (has_edge(mesh_.connectivity(), tip, end) && distance(reference(tip), reference(end)) < options_.eps_edge &&
          keeps_facing(tip, reference(end), end) && collapse_edge(mesh_, end, tip, 0).done) {
        ++report.edges_contracted;
        incision_vertices_.erase(tip);
        forget(tip);
      }
}

void SurfaceCutter::end_at_node(VertexId b, VertexId w, PlanarCutResult& report) {
  std::vector<VertexId> met{b};
  for (VertexId a : active_neighbours(w, b)) met.push_back(a);
  if (!join_at(w, met).empty() && met.size() > 1) ++report.annihilations;
}

std::vector<VertexId> SurfaceCutter::join_at(VertexId w, const std::vector<VertexId>& actives) {
  std::vector<std::array<VertexId, 2>> edges;
  for (VertexId a : actives) {
    std::erase_if(incisions_, [a](const Incision& i) { return i.active == a; });
    edges.push_back({a, w});
  }
  std::vector<VertexId> copies = dissect_edges(edges);
  if (copies.empty()) return {};
  for (VertexId v : copies) incision_vertices_.insert(v), touched_.push_back(v);
  for (VertexId v : actives) incision_vertices_.insert(v), touched_.push_back(v);
  incision_vertices_.insert(w);
  touched_.push_back(w);
  // As at an exit in 2D (§5.2.2, forbidden edges): where incisions ended, the scalpel that is
  // still there enters nothing new in this move, nor later while it stays near (move()).
  std::vector<VertexId> ended = copies;
  ended.insert(ended.end(), actives.begin(), actives.end());
  ended.push_back(w);
  for (VertexId v : ended) {
    ended_.insert(v);
    for (ElementId e : local_star(mesh_.connectivity(), v).elements) refused_.insert(e);
  }
  return copies;
}

void SurfaceCutter::legalize(PlanarCutResult& report) {
  std::sort(touched_.begin(), touched_.end());
  touched_.erase(std::unique(touched_.begin(), touched_.end()), touched_.end());
  const Connectivity& c = mesh_.connectivity();
  // Lawson flips around the vertices this move touched, a bounded number of rounds (on a
  // curved surface the unfolded criterion is a heuristic, §5.3.1).
  for (int round = 0; round < 8; ++round) {
    bool flipped = false;
    const std::vector<VertexId> around = touched_;
    for (VertexId v : around) {
      if (!mesh_.is_vertex(v) || c.n_vertex_uses(v) == 0) continue;
      for (const Wedge& w : wedges(v))
        for (const auto& [p, q] : {std::pair{v, w.y}, std::pair{w.y, w.z}}) {
          // An earlier flip may have replaced the triangle (and its id been reused).
          const bool still = c.is_element(w.element) && c.element(w.element).simplex.contains(p) &&
                             c.element(w.element).simplex.contains(q);
          if (still && !is_locally_delaunay(mesh_, w.element, p, q) && flip(p, q, report)) flipped = true;
        }
    }
    if (!flipped) break;
  }
}

std::vector<VertexId> SurfaceCutter::incision_edges() const { return lip_edges(mesh_.connectivity(), incision_vertices_); }

}  // namespace snede
