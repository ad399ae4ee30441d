#include "cutting/delaunay_cutter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "core/predicates.hpp"
#include "cutting/cut_thresholds.hpp"
#include "cutting/incision_star.hpp"
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

using Point = std::array<double, 2>;

Point minus(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1]}; }
double cross(const Point& a, const Point& b) { return a[0] * b[1] - a[1] * b[0]; }
double distance(const Point& a, const Point& b) { return std::hypot(a[0] - b[0], a[1] - b[1]); }
Point lerp(const Point& a, const Point& b, double t) { return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])}; }

// Barycentric coordinates of x in triangle (a, b, c).
std::array<double, 3> barycentric(const Point& a, const Point& b, const Point& c, const Point& x) {
  const double area = cross(minus(b, a), minus(c, a));
  const double lb = cross(minus(x, a), minus(c, a)) / area, lc = cross(minus(b, a), minus(x, a)) / area;
  return {1 - lb - lc, lb, lc};
}

// Where segment p→q crosses segment a→b: (fraction along pq, fraction along ab), exact
// about whether they meet (touching counts), or nothing.
std::optional<std::pair<double, double>> segments_cross(const Point& p, const Point& q, const Point& a, const Point& b) {
  const int sa = orientation_2d(p.data(), q.data(), a.data()), sb = orientation_2d(p.data(), q.data(), b.data());
  if ((sa > 0 && sb > 0) || (sa < 0 && sb < 0) || (sa == 0 && sb == 0)) return std::nullopt;
  const int sp = orientation_2d(a.data(), b.data(), p.data()), sq = orientation_2d(a.data(), b.data(), q.data());
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0)) return std::nullopt;
  const Point d = minus(q, p), e = minus(b, a);
  const double denominator = cross(d, e);
  if (denominator == 0) return std::nullopt;
  const double s = cross(minus(a, p), e) / denominator, t = cross(minus(a, p), d) / denominator;
  return std::pair{std::clamp(s, 0.0, 1.0), std::clamp(t, 0.0, 1.0)};
}

// Where the line through p and q meets segment (a, b), as a fraction along it clamped to [0, 1]
// (0.5 if they are parallel).
double line_crossing(const Point& p, const Point& q, const Point& a, const Point& b) {
  const Point d = minus(q, p), e = minus(b, a);
  const double denominator = cross(d, e);
  if (denominator == 0) return 0.5;
  return std::clamp(cross(minus(a, p), d) / denominator, 0.0, 1.0);
}

// Interior angle at w of triangle (w, a, b).
double angle_at(const Point& w, const Point& a, const Point& b) {
  const Point u = minus(a, w), v = minus(b, w);
  return std::atan2(std::abs(cross(u, v)), u[0] * v[0] + u[1] * v[1]);
}

}  // namespace

DelaunayCutter::DelaunayCutter(Mesh& mesh, DisplacementSource displacement, DelaunayCutterOptions options)
    : mesh_(mesh),
      displacement_(std::move(displacement)),
      options_(options),
      watch_(mesh.connectivity(), incision_vertices_,
             [this](const Connectivity& c, const IncisionWatch::Fates& fates) { settle(c, fates); }) {
  watch_.forget_removed_from(forbidden_);
  if (mesh.cell_dim() != 2 || mesh.space_dim() != 2)
    throw std::invalid_argument("DelaunayCutter: the mesh must be a 2D triangle mesh, got cell_dim " +
                                std::to_string(mesh.cell_dim()) + " in " + std::to_string(mesh.space_dim()) + "D");
  require(options.short_edge_angle >= 0 && options.short_edge_angle < std::acos(-1.0) / 2,
          "DelaunayCutter: short_edge_angle", "in [0, π/2) radians", options.short_edge_angle);
  // §5.4: thresholds as fractions of the mean edge length.
  static_cast<CutThresholds&>(options_) = resolved_thresholds("DelaunayCutter", mesh, options);
}

DelaunayCutter::Point DelaunayCutter::reference(VertexId v) const {
  const auto x = mesh_.point(v);
  return {x[0], x[1]};
}

DelaunayCutter::Point DelaunayCutter::deformed(VertexId v, std::span<const double> u) const {
  const Point3 x = deformed_point(mesh_, u, v);
  return {x[0], x[1]};
}

ElementId DelaunayCutter::locate(const Point& x, std::span<const double> u, VertexId from) const {
  const Connectivity& c = mesh_.connectivity();
  const auto at = [&](VertexId v) { return deformed(v, u); };
  // Walk towards x, across the side x lies beyond, from the triangle of `from`'s star whose
  // corner at `from` opens towards x: beside an incision (a slit in the body) a walk from
  // another triangle of the star would run into the lips.
  ElementId e = no_id;
  if (from >= 0 && mesh_.is_vertex(from) && c.n_vertex_uses(from) > 0) {
    e = c.vertex_element(from);
    const Point o = at(from);
    for (const Wedge& w : wedges(from))
      if (orientation_2d(o.data(), at(w.y).data(), x.data()) >= 0 && orientation_2d(o.data(), x.data(), at(w.z).data()) >= 0) {
        e = w.element;
        break;
      }
  }
  for (int step = 0; e != no_id && step < 4096; ++step) {
    const auto t = c.element(e).simplex.oriented_vertices();
    int beyond = -1;
    for (int j = 0; j < 3 && beyond < 0; ++j)
      if (orientation_2d(at(t[(j + 1) % 3]).data(), at(t[(j + 2) % 3]).data(), x.data()) < 0) beyond = j;
    if (beyond < 0) return e;
    e = c.neighbor(e, c.element(e).simplex.index(t[beyond]));
  }
  // Walked out of the body (x outside, or a concave body in the way) or no start: scan.
  for (ElementId f = 0; f < c.element_capacity(); ++f) {
    if (!c.is_element(f)) continue;
    const auto t = c.element(f).simplex.oriented_vertices();
    const Point p0 = at(t[0]), p1 = at(t[1]), p2 = at(t[2]);
    if (orientation_2d(p0.data(), p1.data(), x.data()) >= 0 && orientation_2d(p1.data(), p2.data(), x.data()) >= 0 &&
        orientation_2d(p2.data(), p0.data(), x.data()) >= 0)
      return f;
  }
  return no_id;
}

std::optional<DelaunayCutter::Point> DelaunayCutter::to_reference(const Point& x, std::span<const double> u,
                                                                 VertexId from) const {
  const ElementId host = locate(x, u, from);
  if (host == no_id) return std::nullopt;
  if (u.empty()) return x;
  // §5.5: the barycentric coordinates in the deformed triangle, applied to its reference corners.
  const auto t = mesh_.connectivity().element(host).simplex.oriented_vertices();
  const auto l = barycentric(deformed(t[0], u), deformed(t[1], u), deformed(t[2], u), x);
  Point X{0, 0};
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 2; ++d) X[d] += l[k] * reference(t[k])[d];
  return X;
}

DelaunayCutter::Point DelaunayCutter::target_of(const Point& x, std::span<const double> u) const {
  if (u.empty()) return x;
  if (const auto inside = to_reference(x, u, active_)) return *inside;
  // Outside the deformed body: extend the affine map of the active triangle that x faces.
  const Point xb = deformed(active_, u);
  std::optional<Wedge> facing;
  for (const Wedge& w : wedges(active_)) {
    const Point y = deformed(w.y, u), z = deformed(w.z, u);
    if (cross(minus(y, xb), minus(x, xb)) >= 0 && cross(minus(x, xb), minus(z, xb)) >= 0) facing = w;
  }
  if (!facing) facing = wedges(active_).front();
  const auto l = barycentric(xb, deformed(facing->y, u), deformed(facing->z, u), x);
  const Point Xb = reference(active_), Y = reference(facing->y), Z = reference(facing->z);
  return {l[0] * Xb[0] + l[1] * Y[0] + l[2] * Z[0], l[0] * Xb[1] + l[1] * Y[1] + l[2] * Z[1]};
}

std::vector<Wedge> DelaunayCutter::wedges(VertexId b) const { return star_wedges(mesh_.connectivity(), b); }

bool DelaunayCutter::on_boundary(VertexId v) const { return touches_boundary(mesh_.connectivity(), v); }

std::optional<DelaunayCutter::Crossing> DelaunayCutter::first_boundary_crossing(const Point& from, const Point& to,
                                                                               std::span<const double> u) const {
  std::optional<Crossing> first;
  for (const auto& [simplex, f] : mesh_.connectivity().boundary()) {
    const auto ends = simplex.oriented_vertices();
    const VertexId y = ends[0], z = ends[1];
    if (exit_point_ && (forbidden_.count(y) || forbidden_.count(z))) continue;
    const auto hit = segments_cross(from, to, deformed(y, u), deformed(z, u));
    if (hit && (!first || hit->first < first->s)) first = Crossing{y, z, hit->second, hit->first};
  }
  return first;
}

PlanarCutResult DelaunayCutter::move(std::span<const double> point) {
  if (point.size() != 2)
    throw std::invalid_argument("DelaunayCutter.move: the scalpel is a point, 2 coordinates; got " + std::to_string(point.size()));
  require_finite_points(point.data(), point.size(), 2, "DelaunayCutter.move", "point");
  CutterMove this_move(watch_, mesh_);
  PlanarCutResult& report = this_move.report();
  const Point now{point[0], point[1]};
  if (exit_point_ && distance(now, *exit_point_) > 2 * options_.eps_exit) {
    exit_point_.reset();
    forbidden_.clear();
  }
  // Deformed-space questions first: the edits below work in the reference configuration.
  std::optional<Crossing> crossing;
  std::optional<Point> inside;
  Point target{};
  {
    const DisplacementRead read = displacement_ ? displacement_() : DisplacementRead{};
    const std::span<const double> u = read.values;
    if (phase_ == Phase::outside && scalpel_) crossing = first_boundary_crossing(*scalpel_, now, u);
    if (phase_ == Phase::cutting)
      target = target_of(now, u);
    else if (phase_ == Phase::entering)
      inside = to_reference(now, u, active_);
    else if (crossing)  // about to enter: walk from the boundary edge crossed
      inside = to_reference(now, u, crossing->y);
  }
  scalpel_ = now;
  touched_.clear();
  // A body hears of the move's edits at once: its vectors are reissued once per move.
  std::optional<ChangeBatch> batch;
  batch.emplace(mesh_.connectivity());

  if (phase_ == Phase::outside && crossing) enter(*crossing, report);
  if (phase_ == Phase::entering) {
    if (!inside)
      phase_ = Phase::outside;  // withdrawn before the incision began: the entry node stays
    else if (distance(*inside, entry_) > options_.eps_entry && fix_up_entry(*inside, report))
      last_target_ = *inside;
  } else if (phase_ == Phase::cutting) {
    const Point from = last_target_ ? *last_target_ : reference(active_);
    if (!advance(target, report)) {
      if (phase_ == Phase::cutting) ++report.stuck;
    }
    if (phase_ == Phase::cutting) {
      last_target_ = target;
      if (trail_.empty() || trail_.back() != reference(active_)) trail_.push_back(reference(active_));
      split_incision(report);
      predict_exit(minus(target, from), report);
    }
  }
  if (phase_ == Phase::cutting) touched_.push_back(active_);
  legalize(report);
  batch.reset();
  watch_.follow(phase_ == Phase::outside ? std::span<const VertexId>{} : std::span<const VertexId>(&active_, 1));
  return this_move.finished();
}

void DelaunayCutter::legalize(PlanarCutResult& report) {
  const Connectivity& c = mesh_.connectivity();
  std::sort(touched_.begin(), touched_.end());
  touched_.erase(std::unique(touched_.begin(), touched_.end()), touched_.end());
  // An edge (p, q) waits with a triangle holding it, so that checking it costs one neighbour
  // look-up; only when a flip or removal replaced that triangle is the edge searched again.
  struct EdgeInTriangle {
    ElementId triangle;
    VertexId p, q;
  };
  std::vector<EdgeInTriangle> queue;
  for (VertexId v : touched_)
    if (mesh_.is_vertex(v) && c.n_vertex_uses(v) > 0)
      for (const Wedge& w : wedges(v)) queue.insert(queue.end(), {{w.element, v, w.y}, {w.element, w.y, w.z}});
  for (std::size_t done = 0; !queue.empty() && done < 64 * (touched_.size() + 16); ++done) {
    auto [e, p, q] = queue.back();
    queue.pop_back();
    if (!c.is_element(e) || !c.element(e).simplex.contains(p) || !c.element(e).simplex.contains(q)) {
      if (!mesh_.is_vertex(p) || !mesh_.is_vertex(q)) continue;
      const std::vector<ElementId> sharing = elements_with_edge(c, p, q);
      if (sharing.empty()) continue;
      e = sharing.front();
    }
    if (is_locally_delaunay(mesh_, e, p, q)) continue;
    const VertexId r = third_vertex(c.element(e).simplex, p, q);
    const VertexId s = third_vertex(c.element(c.neighbor(e, c.element(e).simplex.index(r))).simplex, p, q);
    if (!flip_edge(mesh_, p, q).done) continue;
    ++report.flips;
    // The new edge (r, s) has the quadrilateral's four sides around it: check them again.
    for (ElementId side : elements_with_edge(c, r, s))
      for (VertexId end : {p, q})
        if (c.element(side).simplex.contains(end)) queue.insert(queue.end(), {{side, end, r}, {side, end, s}});
  }
}

void DelaunayCutter::lift() {
  phase_ = Phase::outside;
  active_ = -1;
  scalpel_.reset();
  last_target_.reset();
  trail_.clear();
  watch_.follow({});
}

void DelaunayCutter::settle(const Connectivity& c, const IncisionWatch::Fates& fates) {
  if (phase_ == Phase::outside) return;
  const auto fate = fates.find(active_);
  const std::vector<VertexId> heirs = fate == fates.end() ? std::vector<VertexId>{active_} : fate->second.heirs;
  for (VertexId v : heirs) {
    // An entry node waits on the boundary; a cut's tip has the two cut edges (§5.2.2).
    const bool carries = phase_ == Phase::entering ? c.n_vertex_uses(v) > 0 && on_boundary(v)
                                                   : is_incision_tip(mesh_, v, incision_vertices_, fate != fates.end());
    if (!carries) continue;
    if (phase_ == Phase::entering) entry_ = reference(v);
    active_ = v;
    watch_.follow(std::span<const VertexId>(&active_, 1));
    return;
  }
  watch_.lose("DelaunayCutter.move: edits made to the mesh since the last move took the incision's active node " +
              std::to_string(active_) + " away (" +
              (fate == fates.end() ? "it is no longer the incision's tip" : fate->second.change) +
              ") and left no vertex that is the incision's tip; the scalpel is lifted: the next move only places it");
  lift();
}

void DelaunayCutter::enter(const Crossing& crossing, PlanarCutResult& report) {
  const Point y = reference(crossing.y), z = reference(crossing.z);
  const Point at = lerp(y, z, crossing.lambda);
  VertexId a = -1;
  if (distance(at, y) <= options_.eps_entry || crossing.lambda <= 0)
    a = crossing.y;
  else if (distance(at, z) <= options_.eps_entry || crossing.lambda >= 1)
    a = crossing.z;
  else if (const EditResult split = split_edge(mesh_, crossing.y, crossing.z, crossing.lambda); split.done) {
    a = split.vertex;
    ++report.nodes_inserted;
    if (incision_vertices_.count(crossing.y) && incision_vertices_.count(crossing.z)) incision_vertices_.insert(a);  // on a lip
  } else {
    a = distance(at, y) < distance(at, z) ? crossing.y : crossing.z;
  }
  active_ = a;
  entry_ = reference(a);
  phase_ = Phase::entering;
  touched_.push_back(a);
  ++report.entries;
}

bool DelaunayCutter::fix_up_entry(const Point& p, PlanarCutResult& report) {
  const Connectivity& c = mesh_.connectivity();
  const VertexId a = active_;
  // The node at the scalpel: inserted in the triangle that holds p, or on its nearest edge.
  const ElementId host = locate(p, {}, active_);
  if (host == no_id) return false;
  const auto t = c.element(host).simplex.oriented_vertices();
  const std::array<VertexId, 3> corners{t[0], t[1], t[2]};
  auto weights = barycentric(reference(t[0]), reference(t[1]), reference(t[2]), p);
  for (double& w : weights) w = std::max(w, 0.0);
  const double sum = weights[0] + weights[1] + weights[2];
  for (double& w : weights) w /= sum;
  EditResult made = insert_vertex(mesh_, host, weights);
  if (!made.done) {  // on or too near a side: split that side at p's projection
    const int k = static_cast<int>(std::min_element(weights.begin(), weights.end()) - weights.begin());
    // On a boundary side (an incision's lip, most often) the new incision would run along
    // the boundary: the entry stays postponed until the scalpel is in the material.
    if (is_boundary_edge(c, host, corners[k])) return false;
    const VertexId s = corners[(k + 1) % 3], t = corners[(k + 2) % 3];
    const double along = weights[(k + 2) % 3] / (weights[(k + 1) % 3] + weights[(k + 2) % 3]);
    made = split_edge(mesh_, s, t, std::clamp(along, 0.05, 0.95));
  }
  if (!made.done) return false;
  const VertexId b = made.vertex;
  ++report.nodes_inserted;
  active_ = b;
  remesh_around(b, report);
  if (!mesh_.is_vertex(a) || !recover_edge(a, b, report)) {
    remove_node(b, report);
    active_ = a;
    return false;
  }
  for (VertexId v : dissect_edge(a, b)) incision_vertices_.insert(v), touched_.push_back(v);
  touched_.insert(touched_.end(), {a, b});
  incision_vertices_.insert(a);
  incision_vertices_.insert(b);
  phase_ = Phase::cutting;
  trail_ = {reference(a), reference(b)};
  return true;
}

bool DelaunayCutter::recover_edge(VertexId a, VertexId b, PlanarCutResult& report) {
  const Point pa = reference(a), pb = reference(b);
  for (int attempt = 0; attempt < 64; ++attempt) {
    if (has_edge(mesh_.connectivity(), a, b)) return true;
    std::optional<Wedge> through;
    for (const Wedge& w : wedges(a))
      if (orientation_2d(pa.data(), reference(w.y).data(), pb.data()) >= 0 &&
          orientation_2d(pa.data(), pb.data(), reference(w.z).data()) >= 0)
        through = w;
    if (!through || !flip(through->y, through->z, report)) return false;
  }
  return has_edge(mesh_.connectivity(), a, b);
}

std::vector<VertexId> DelaunayCutter::dissect_edge(VertexId a, VertexId b) {
  Connectivity& c = mesh_.connectivity();
  const std::vector<ElementId> sharing = elements_with_edge(c, a, b);
  const Simplex& t = c.element(sharing.front()).simplex;
  VertexId third = -1;
  for (VertexId v : t.vertices())
    if (v != a && v != b) third = v;
  const FaceId face = c.opposite_face(sharing.front(), third);
  const std::vector<SplitVertex> split =
      dissect(c, std::span<const FaceId>(&face, 1), [this](VertexId v) { return mesh_.add_vertex(VertexParents::copy_of(v)); });
  std::vector<VertexId> copies;
  for (const SplitVertex& s : split) copies.push_back(s.copy);
  return copies;
}

bool DelaunayCutter::move_active_to(const Point& x) {
  // Parents from the star triangle holding x, so a body's fields are interpolated there.
  std::optional<Wedge> best;
  double best_min = -std::numeric_limits<double>::infinity();
  std::array<double, 3> weights{};
  const Point b = reference(active_);
  for (const Wedge& w : wedges(active_)) {
    const auto l = barycentric(b, reference(w.y), reference(w.z), x);
    if (const double m = std::min({l[0], l[1], l[2]}); m > best_min) best_min = m, best = w, weights = l;
  }
  if (!best || best_min < -1e-9) return false;
  for (double& w : weights) w = std::max(w, 0.0);
  const double sum = weights[0] + weights[1] + weights[2];
  for (double& w : weights) w /= sum;
  const std::array<VertexId, 3> parents{active_, best->y, best->z};
  return snap_vertex(mesh_, active_, VertexParents::barycentric(parents, weights)).done;
}

bool DelaunayCutter::advance(const Point& target, PlanarCutResult& report) {
  for (int step = 0; step < 256; ++step) {
    const Point x = reference(active_);
    const Point d = minus(target, x);
    if (d[0] == 0 && d[1] == 0) return true;
    // The first active triangle the straight way to the target would invert.
    double t_hit = std::numeric_limits<double>::infinity();
    std::optional<Wedge> blocking;
    for (const Wedge& w : wedges(active_)) {
      const Point y = reference(w.y), z = reference(w.z);
      const double now = cross(minus(y, x), minus(z, x)), then = cross(minus(y, target), minus(z, target));
      if (then > 0) continue;
      if (const double t = now / (now - then); t < t_hit) t_hit = t, blocking = w;
    }
    if (!blocking) {
      if (move_active_to(target)) {
        remesh_around(active_, report);
        return true;
      }
      t_hit = 1;  // rounding at the target: step part of the way instead
    }
    if (!move_active_to({x[0] + 0.6 * t_hit * d[0], x[1] + 0.6 * t_hit * d[1]})) return false;
    if (blocking) {
      const Connectivity& c = mesh_.connectivity();
      const FaceId ahead = c.opposite_face(blocking->element, active_);
      if (c.is_face(ahead) && c.face(ahead).mate == no_id) {
        // The way leaves the body: the cut exits through the boundary edge of the star that
        // the way crosses. Two collinear boundary edges tie for the first triangle to invert,
        // so the blocking one need not be it.
        VertexId y = blocking->y, z = blocking->z;
        double lambda = line_crossing(x, target, reference(y), reference(z));
        for (const Wedge& w : wedges(active_)) {
          if (!is_boundary_edge(c, w.element, active_)) continue;
          if (const auto hit = segments_cross(x, target, reference(w.y), reference(w.z))) {
            y = w.y, z = w.z, lambda = hit->second;
            break;
          }
        }
        exit_through(y, z, lambda, report);
        return false;
      }
      if (c.is_face(ahead) && c.face(ahead).mate != no_id) {
        if (!flip(blocking->y, blocking->z, report)) {
          // A reflex corner ahead: remove the nearer interior end of the edge, if either is.
          const Point here = reference(active_);
          VertexId first = blocking->y, second = blocking->z;
          if (distance(reference(second), here) < distance(reference(first), here)) std::swap(first, second);
          bool removed = false;
          for (VertexId v : {first, second})
            if (!removed && !on_boundary(v)) removed = remove_node(v, report);
          if (!removed) return false;
        }
      }
    }
    remesh_around(active_, report);
  }
  return false;
}

void DelaunayCutter::remesh_around(VertexId b, PlanarCutResult& report) {
  const Connectivity& c = mesh_.connectivity();
  // Flips towards Delaunay: the edges of the active triangles (spokes and link edges).
  flip_star_towards_delaunay(mesh_, b, [&](VertexId p, VertexId q) { return flip(p, q, report); });
  // Interior nodes too close to the active node (§5.2.2), by distance or by angles (§5.5).
  for (int round = 0; round < 16; ++round) {
    const Point x = reference(b);
    VertexId closest = -1;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Wedge& w : wedges(b))
      for (VertexId v : {w.y, w.z}) {
        bool too_close = false;
        if (options_.short_edge_angle > 0) {
          too_close = true;
          for (ElementId e : elements_with_edge(c, b, v)) {
            VertexId third = -1;
            for (VertexId t : c.element(e).simplex.vertices())
              if (t != b && t != v) third = t;
            if (angle_at(reference(third), x, reference(v)) >= options_.short_edge_angle) too_close = false;
          }
        } else {
          too_close = distance(reference(v), x) < options_.eps_edge;
        }
        // Only interior nodes go (the boundary's shape stays); the cheap tests first.
        if (too_close && distance(reference(v), x) < nearest && !incision_vertices_.count(v) && !on_boundary(v))
          nearest = distance(reference(v), x), closest = v;
      }
    if (closest < 0 || !remove_node(closest, report)) break;
  }
}

bool DelaunayCutter::flip(VertexId p, VertexId q, PlanarCutResult& report) {
  std::vector<VertexId> quad{p, q};
  for (ElementId e : elements_with_edge(mesh_.connectivity(), p, q))
    for (VertexId v : mesh_.connectivity().element(e).simplex.vertices()) quad.push_back(v);
  if (!flip_edge(mesh_, p, q).done) return false;
  ++report.flips;
  touched_.insert(touched_.end(), quad.begin(), quad.end());
  return true;
}

bool DelaunayCutter::remove_node(VertexId v, PlanarCutResult& report) {
  std::vector<VertexId> link;
  for (const Wedge& w : wedges(v)) link.insert(link.end(), {w.y, w.z});
  if (!remove_vertex_by_flips(mesh_, v).done) return false;
  ++report.nodes_removed;
  touched_.insert(touched_.end(), link.begin(), link.end());
  return true;
}

std::optional<DelaunayCutter::TrailCrossing> DelaunayCutter::trail_crossing(const Point& p, const Point& q,
                                                                           const Point& near) const {
  std::optional<TrailCrossing> best;
  for (std::size_t k = 0; k + 1 < trail_.size(); ++k)
    if (const auto hit = segments_cross(p, q, trail_[k], trail_[k + 1])) {
      const Point x = lerp(p, q, hit->first);
      if (!best || distance(x, near) < distance(best->point, near)) best = TrailCrossing{x, k};
    }
  return best;
}

bool DelaunayCutter::move_lips_to(const Point& x, std::array<VertexId, 2> copies,
                                  std::array<std::array<VertexId, 3>, 2> own_triangles) {
  // Each copy moves with the barycentric coordinates of x in its own lip's triangle (b, c, o),
  // extrapolating for the copy on the far side, so a body's fields follow each lip's side.
  const auto snap = [&](int k, const Point& to) {
    const auto& [b, c, o] = own_triangles[k];
    const auto weights = barycentric(reference(b), reference(c), reference(o), to);
    return snap_vertex(mesh_, copies[k], VertexParents::barycentric(own_triangles[k], weights)).done;
  };
  const Point chord = reference(copies[0]);
  if (!snap(0, x)) return false;
  if (!snap(1, x)) {  // back to the chord, where the other copy still is
    snap(0, chord);
    mesh_.move_vertex(copies[0], reference(copies[1]));
    return false;
  }
  // The two copies' weights differ: the second takes the first's coordinates, bit for bit.
  const Point first = reference(copies[0]);
  mesh_.move_vertex(copies[1], first);
  return true;
}

void DelaunayCutter::split_incision(PlanarCutResult& report) {
  const Connectivity& c = mesh_.connectivity();
  const VertexId b = active_;
  // The cut edges: boundary edges b→c1 (in the wedge (b, c1, o1)) and c2→b (in (b, o2, c2)).
  std::optional<Wedge> out, in;
  for (const Wedge& w : wedges(b)) {
    if (is_boundary_edge(c, w.element, w.z)) out = w;
    if (is_boundary_edge(c, w.element, w.y)) in = w;
  }
  if (!out || !in || out->element == in->element) return;
  const VertexId c1 = out->y, o1 = out->z, o2 = in->y, c2 = in->z;
  if (o1 == o2 || !incision_vertices_.count(c1) || !incision_vertices_.count(c2)) return;
  const Point pb = reference(b), pc = lerp(reference(c1), reference(c2), 0.5), p1 = reference(o1), p2 = reference(o2);
  // Figure 5.5: is b–c, the cut edges seen as one edge, a Delaunay diagonal of (b, o2, c, o1)?
  int orientation = orientation_2d(pb.data(), p2.data(), pc.data());
  if (orientation == 0) return;
  const int inside = orientation > 0 ? in_circle(pb.data(), p2.data(), pc.data(), p1.data())
                                     : in_circle(pb.data(), pc.data(), p2.data(), p1.data());
  if (inside <= 0) return;
  // New nodes where the line o1 o2 crosses the cut edges: fraction s from b towards c.
  const Point e = minus(p2, p1), bc = minus(pc, pb);
  const double denominator = cross(bc, e);
  if (denominator == 0) return;
  const double s = cross(minus(p1, pb), e) / denominator;
  const double length = distance(pb, pc);
  if (!(s * length > 0.25 * options_.eps_edge && (1 - s) * length > 0.25 * options_.eps_edge)) return;
  // §5.2.2: the new nodes go where o1 o2 crosses the scalpel's path (its trail since c);
  // where it does not, on the chord.
  const Point at = lerp(pb, pc, s);
  const std::optional<TrailCrossing> on_path = trail_crossing(p1, p2, at);
  const Point node = on_path ? on_path->point : at;
  if (!(distance(node, pb) > 0.25 * options_.eps_edge && distance(node, pc) > 0.25 * options_.eps_edge)) return;
  // A new incision node within ε_edge/2 of o1 or o2 would leave a sliver: the interior node
  // goes instead, as one that near the active node does (§5.2.2), and the next move looks
  // again; next to a boundary node the incision stays unsplit. (Removing within ε_edge gives
  // larger angles still but an incision further from the path: docs/results/delaunay_cut.md.)
  const VertexId nearer = distance(node, p1) < distance(node, p2) ? o1 : o2;
  if (distance(node, reference(nearer)) < 0.5 * options_.eps_edge) {
    if (!incision_vertices_.count(nearer) && !on_boundary(nearer) && remove_node(nearer, report)) remesh_around(b, report);
    return;
  }
  const EditResult first = split_edge(mesh_, b, c1, s);
  if (!first.done) return;
  const EditResult second = split_edge(mesh_, b, c2, s);
  if (!second.done) {  // keep the lips alike: undo the first
    collapse_edge(mesh_, c1, first.vertex, 0);
    return;
  }
  if (on_path && move_lips_to(on_path->point, {first.vertex, second.vertex}, {{{b, c1, o1}, {b, c2, o2}}})) {
    trail_.erase(trail_.begin(), trail_.begin() + static_cast<std::ptrdiff_t>(on_path->segment) + 1);
    trail_.insert(trail_.begin(), on_path->point);
  } else {
    trail_ = {at, reference(b)};
  }
  incision_vertices_.insert(first.vertex);
  incision_vertices_.insert(second.vertex);
  touched_.insert(touched_.end(), {first.vertex, second.vertex});
  report.nodes_inserted += 2;
  ++report.incision_splits;
  remesh_around(b, report);
}

void DelaunayCutter::predict_exit(const Point& direction, PlanarCutResult& report) {
  const double length = std::hypot(direction[0], direction[1]);
  if (length == 0 || phase_ != Phase::cutting) return;
  const Point x = reference(active_);
  const Point ahead{x[0] + options_.eps_exit * direction[0] / length, x[1] + options_.eps_exit * direction[1] / length};
  const Connectivity& c = mesh_.connectivity();
  for (const Wedge& w : wedges(active_)) {
    if (!is_boundary_edge(c, w.element, active_)) continue;
    if (const auto hit = segments_cross(x, ahead, reference(w.y), reference(w.z))) {
      exit_through(w.y, w.z, hit->second, report);
      return;
    }
  }
}

void DelaunayCutter::exit_through(VertexId y, VertexId z, double lambda, PlanarCutResult& report) {
  const Point py = reference(y), pz = reference(z), at = lerp(py, pz, lambda);
  VertexId w = -1;
  if (distance(at, py) <= options_.eps_exit)
    w = y;
  else if (distance(at, pz) <= options_.eps_exit)
    w = z;
  else if (const EditResult split = split_edge(mesh_, y, z, lambda); split.done) {
    w = split.vertex;
    ++report.nodes_inserted;
  } else {
    w = distance(at, py) < distance(at, pz) ? y : z;
  }
  const VertexId b = active_;
  phase_ = Phase::outside;
  active_ = -1;
  last_target_.reset();
  trail_.clear();
  // An edge (b, w) that is missing, or already on the boundary (w next to b along it), has
  // nothing to open: the incision ends where it is.
  if (elements_with_edge(mesh_.connectivity(), b, w).size() != 2) return;
  const std::vector<VertexId> copies = dissect_edge(b, w);
  ++report.exits;
  // Contract the short edges the exit leaves (Figure 5.7): each copy of b into its copy of w.
  std::vector<VertexId> tips{b}, ends{w};
  for (VertexId v : copies) (mesh_.is_vertex(v) && mesh_.parents(v).vertex.front() == b ? tips : ends).push_back(v);
  forbidden_.clear();
  for (VertexId tip : tips)
    for (VertexId end : ends)
      if (has_edge(mesh_.connectivity(), tip, end) && distance(reference(tip), reference(end)) < options_.eps_edge &&
          collapse_edge(mesh_, end, tip, 0).done) {
        ++report.edges_contracted;
        incision_vertices_.erase(tip);
      }
  for (VertexId v : ends) incision_vertices_.insert(v), forbidden_.insert(v), touched_.push_back(v);
  for (VertexId v : tips)
    if (mesh_.is_vertex(v)) incision_vertices_.insert(v), forbidden_.insert(v), touched_.push_back(v);
  exit_point_ = scalpel_;
}

std::vector<VertexId> DelaunayCutter::incision_edges() const { return lip_edges(mesh_.connectivity(), incision_vertices_); }

}  // namespace snede
