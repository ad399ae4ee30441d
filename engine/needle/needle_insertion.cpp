#include "needle/needle_insertion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "core/log_event.hpp"
#include "core/petsc_util.hpp"
#include "needle/move_extension.hpp"
#include "topology/refine_around.hpp"
#include "topology/refine_near_segment.hpp"

namespace snede {
namespace {

// Where the shaft first crosses the body's boundary, along it: the nearest boundary crossing.
std::optional<double> first_boundary_crossing(const std::vector<ShaftCrossing>& crossings) {
  std::optional<double> first;
  for (const ShaftCrossing& c : crossings)
    if (c.on_boundary && (!first || c.s < *first)) first = c.s;
  return first;
}

std::string point_text(const Point& x, int dim) {
  std::ostringstream text;
  text << "(";
  for (int k = 0; k < dim; ++k) text << (k ? ", " : "") << x[k];
  text << ")";
  return text.str();
}

}  // namespace

void NeedleOptions::validate() const {
  if (!(static_factor >= 1.0) || !std::isfinite(static_factor))
    throw std::invalid_argument("static_factor must be at least 1 (static friction ≥ dynamic), got " +
                                std::to_string(static_factor));
  if (h_ref && (!(*h_ref > 0) || !std::isfinite(*h_ref)))
    throw std::invalid_argument("h_ref must be positive and finite, got " + std::to_string(*h_ref));
  if (radius && (!(*radius > 0) || !std::isfinite(*radius)))
    throw std::invalid_argument("radius must be positive and finite, got " + std::to_string(*radius));
  if (max_rearrangements < 1)
    throw std::invalid_argument("max_rearrangements must be at least 1, got " + std::to_string(max_rearrangements));
  if (solves_per_update < 0)
    throw std::invalid_argument("solves_per_update must be 0 (until settled) or positive, got " +
                                std::to_string(solves_per_update));
  if (extension_rings < 0)
    throw std::invalid_argument("extension_rings must be 0 (halve at once) or positive, got " +
                                std::to_string(extension_rings));
  if (friction_channel.empty()) throw std::invalid_argument("friction_channel must name a load channel");
}

StaticOptions NeedleInsertion::default_solver_options() {
  StaticOptions options;
  options.method = StaticMethod::linear_cg;
  options.stopping.rtol = 1e-3;
  options.stopping.round_tolerance = 1e-8;
  options.options_prefix = "needle_";
  return options;
}

NeedleInsertion::NeedleInsertion(Model& model, Bisection* bisection, const Point& entry, const Point& direction,
                                 FrictionProfile friction, NeedleOptions options, StaticOptions solver_options)
    : model_(model), bisection_(bisection), dim_(model.dim()), friction_(std::move(friction)), options_(std::move(options)) {
  if (model_.body().mesh().is_surface())
    throw std::invalid_argument("needle insertion needs a 2D plane-stress or a 3D tetrahedral body, not a surface");
  entry_ = {0, 0, 0};
  Point axis{0, 0, 0};
  for (int k = 0; k < dim_; ++k) {
    entry_[k] = entry[k];
    axis[k] = direction[k];
  }
  if (!std::all_of(entry_.begin(), entry_.end(), [](double x) { return std::isfinite(x); }))
    throw std::invalid_argument("needle entry must be finite, got " + point_text(entry_, dim_));
  const double length = norm(axis);
  if (!(length > 0) || !std::isfinite(length))
    throw std::invalid_argument("needle direction must be non-zero and finite, got " + point_text(axis, dim_));
  for (int k = 0; k < 3; ++k) direction_[k] = axis[k] / length;
  normal_ = {-direction_[1], direction_[0], 0};
  options_.validate();
  if (dim_ == 2 && options_.radius)
    throw std::invalid_argument("radius is for 3D needles; in 2D the needle is a line, got radius=" +
                                std::to_string(*options_.radius));
  radius_ = dim_ == 3 ? options_.radius.value_or(NeedleOptions::default_radius) : 0.0;
  if (options_.h_ref && !bisection_) throw std::invalid_argument("h_ref needs the mesh's bisection");
  if (!first_contact())
    throw std::invalid_argument("the needle from entry " + point_text(entry_, dim_) + " along " +
                                point_text(direction_, dim_) + " never meets the body");
  const Mesh& mesh = model_.body().mesh();
  // The needle's loop changes the mesh at nearly every update (refinement at the tip), so "mg"
  // takes grid levels, which are rebuilt cheaply, unless told otherwise: on the cube of
  // studies/benchmarks/needle3d_rates.py --haptic (neo-Hookean) 22.3 updates/s against 12.9 with the
  // bisection levels, the same for the linear material. The bisection's hierarchy stays
  // available (-<prefix>mg_coarsening bisection).
  const OptionList& given = solver_options.petsc_options;
  if (std::none_of(given.begin(), given.end(), [](const auto& option) { return option.first == "mg_coarsening"; }))
    solver_options.petsc_options.emplace_back("mg_coarsening", "grid");
  // A planar needle's linear CG solves a small correction per update (20–40 iterations without a
  // preconditioner at ε = 1e-3 on the §6.8.1 slab, 170–1 300 from rest), while refinement and
  // stick-slip change its system at nearly every update, and multigrid's levels with it: no
  // preconditioner was 1.25–2.4× faster up to 4 000 triangles, the two even (0.96–1.06) at
  // 10 000–12 500 (studies/benchmarks/needle_rates.py --crossover). Newton keeps its levels
  // across stick-slip and gained from them at 1 300 triangles already: its default stays.
  if (dim_ == 2 && solver_options.method == StaticMethod::linear_cg)
    solver_options.multigrid_from_cells = planar_linear_multigrid_from_cells;
  solver_ = std::make_unique<StaticSolver>(model_, std::move(solver_options),
                                           bisection_ ? &bisection_->hierarchy() : nullptr);
  node_of_vertex_.assign(mesh.n_points(), -1);
  create_predictor_vectors();
  model_.body().mesh().connectivity().add_watcher(this);
}

NeedleInsertion::~NeedleInsertion() {
  model_.body().mesh().connectivity().remove_watcher(this);
  model_.remove_carried_field(rate_.slot());
  model_.remove_carried_field(start_.slot());
}

void NeedleInsertion::create_predictor_vectors() {
  SNEDE_PETSC(VecDuplicate(model_.displacement(), rate_.out()));
  SNEDE_PETSC(VecDuplicate(model_.displacement(), start_.out()));
  SNEDE_PETSC(VecZeroEntries(rate_));
  model_.add_carried_field(rate_.slot());
  model_.add_carried_field(start_.slot());
}

void NeedleInsertion::extend_move(double distance) {
  std::vector<VertexId> sticking;
  for (const NeedleNode& node : nodes_)
    if (node.sticking) sticking.push_back(node.vertex);
  // Twice as many Jacobi sweeps as rings: enough to smooth the first guess's kinks at the rings.
  const int sweeps = 2 * options_.extension_rings;
  const auto weights =
      move_extension_weights(model_.body().mesh(), model_.constraints(), sticking, options_.extension_rings, sweeps);
  {
    WriteView u(model_.displacement());
    for (const auto& [v, w] : weights)
      for (int k = 0; k < dim_; ++k) u.span()[at(v) + k] += w * distance * direction_[k];
  }
  model_.enforce_constraints(model_.displacement());
}

void NeedleInsertion::predict(double distance) {
  Vec u = model_.displacement();
  SNEDE_PETSC(VecCopy(u, start_));
  if (!options_.extrapolate || !have_rate_ || distance <= 0) return;
  SNEDE_PETSC(VecAXPY(u, distance, rate_));
  model_.enforce_constraints(u);
  if (!model_.admissible(u)) SNEDE_PETSC(VecCopy(start_, u));  // no worse than the last state
}

void NeedleInsertion::record_rate(double distance) {
  if (distance <= 0) return;
  SNEDE_PETSC(VecWAXPY(rate_, -1.0, start_, model_.displacement()));
  SNEDE_PETSC(VecScale(rate_, 1.0 / distance));
  have_rate_ = true;
}

Point NeedleInsertion::point_at(double s) const { return plus_scaled(entry_, s, direction_); }

std::optional<double> NeedleInsertion::first_contact() const {
  const Mesh& mesh = model_.body().mesh();
  const std::vector<double> u = vec_values(model_.displacement());
  if (reference_position(mesh, u, entry_)) return 0.0;
  double reach = 0;
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v)) reach = std::max(reach, distance(deformed_point(mesh, u, v), entry_));
  return first_boundary_crossing(shaft_crossings(mesh, u, entry_, point_at(2 * reach)));
}

double NeedleInsertion::surface_depth() const {
  const std::optional<double> s = first_contact();
  if (!s) throw std::invalid_argument("the needle's line no longer meets the body");
  return *s;
}

double NeedleInsertion::along(const Point& x) const { return dot(minus(x, entry_), direction_); }

double NeedleInsertion::across(const Point& x) const {
  if (dim_ == 2) return (x[0] - entry_[0]) * normal_[0] + (x[1] - entry_[1]) * normal_[1];
  return distance(x, point_at(along(x)));
}

void NeedleInsertion::fix_where_it_is(VertexId v, std::span<const double> u) {
  model_.fix(std::span<const VertexId>(&v, 1), u.subspan(at(v), static_cast<std::size_t>(dim_)));
}

NeedleStepResult NeedleInsertion::advance(double distance) {
  if (!(distance >= 0) || !std::isfinite(distance))
    throw std::invalid_argument("the needle advances by a non-negative, finite distance; got " +
                                std::to_string(distance));
  const ExclusiveUse::Claim claim = model_.exclusive_use().claim("a needle step");
  const double start = wall_seconds();
  NeedleStepResult report = advance_in_steps(distance, 0);
  report.seconds = wall_seconds() - start;
  return report;
}

void NeedleInsertion::move_needle(double distance) {
  depth_ += distance;
  // Sticking nodes move with the needle: their prescribed displacement follows it (§6.7).
  std::vector<VertexId> moved;
  std::vector<double> anchors;
  for (const NeedleNode& node : nodes_) {
    if (!node.sticking) continue;
    const VertexConstraint& c = model_.constraints()[node.vertex];
    moved.push_back(node.vertex);
    for (int k = 0; k < dim_; ++k) anchors.push_back(c.anchor[k] + distance * direction_[k]);
  }
  if (!moved.empty()) model_.fix(moved, anchors);
}

bool NeedleInsertion::move_admissible() const {
  // A sticking node moved by exactly the spacing of the needle nodes lands on the next one (the
  // 2D slab's shaft on a grid line of the h7 mesh, 1 h_ref per update): their cells are flat to
  // round-off, det F of 1e-13, which the inversion test (det F ≤ 0) does not count, and their
  // neo-Hookean forces (4e14 N) stopped Newton (DIVERGED_LINE_SEARCH at the third update). Such
  // a move is carried into the tissue or halved, as one that inverts.
  return model_.admissible(model_.displacement(), nullptr, collapse_floor);
}

NeedleStepResult NeedleInsertion::advance_in_steps(double distance, int halvings) {
  move_needle(distance);
  // A move that drags sticking nodes across their neighbours would start the solve from
  // inverted elements, which a material forbidding inversion cannot relax: carry the move into
  // the tissue around them, else move in halves.
  bool extended = false;
  bool admissible = distance <= 0 || move_admissible();
  if (!admissible && options_.extension_rings > 0) {
    SNEDE_PETSC(VecCopy(model_.displacement(), start_));  // the move without its extension
    extend_move(distance);
    extended = true;
    admissible = move_admissible();
  }
  if (!admissible && halvings < max_halvings) {
    if (extended) SNEDE_PETSC(VecCopy(start_, model_.displacement()));
    move_needle(-distance);
    NeedleStepResult first = advance_in_steps(0.5 * distance, halvings + 1);
    first.halvings += 1;
    if (!first.converged) return first;
    return merged(first, advance_in_steps(0.5 * distance, halvings + 1));
  }
  NeedleStepResult report;
  report.extensions = extended ? 1 : 0;
  predict(distance);
  const std::size_t cells_before = model_.body().mesh().n_cells();
  refine_at_tip();
  report.cells_split = static_cast<int>(model_.body().mesh().n_cells() - cells_before);
  report.intercepted = intercept_nodes();
  report = solve_and_rearrange(report);
  if (report.converged) record_rate(distance);
  return report;
}

NeedleStepResult NeedleInsertion::merged(const NeedleStepResult& a, const NeedleStepResult& b) {
  NeedleStepResult m = b;
  m.rearrangements += a.rearrangements;
  m.slipped += a.slipped;
  m.stuck += a.stuck;
  m.released += a.released;
  m.intercepted += a.intercepted;
  m.cells_split += a.cells_split;
  m.extensions += a.extensions;
  m.halvings += a.halvings;
  m.solver_iterations += a.solver_iterations;
  m.max_solver_iterations = std::max(a.max_solver_iterations, b.max_solver_iterations);
  m.settled = b.settled;
  return m;
}

NeedleStepResult NeedleInsertion::settle() {
  const double start = wall_seconds();
  NeedleStepResult report;
  report.intercepted = intercept_nodes();
  report = solve_and_rearrange(report);
  report.seconds = wall_seconds() - start;
  return report;
}

void NeedleInsertion::refine_at_tip() {
  if (!options_.h_ref || depth_ <= 0) return;
  static const PetscLogEvent event = log_event("SnedeNeedleRefine");
  const ScopedEvent timed(event);
  const std::vector<double> u = vec_values(model_.displacement());
  // Refinement works in the reference configuration: around the material point under the
  // deformed tip, and in 3D along the shaft's image since the last update, within r of it.
  const std::optional<Point> X = reference_position(model_.body().mesh(), u, tip());
  if (!X) return;  // the tip is outside the body
  const std::span<const double> x(X->data(), static_cast<std::size_t>(dim_));
  if (dim_ == 2) {
    refine_around(*bisection_, x, *options_.h_ref);
    return;
  }
  const Point from = refined_from_.value_or(*X);
  refine_near_segment(*bisection_, std::span<const double>(from.data(), 3), x, *options_.h_ref, radius_);
  refined_from_ = X;
}

void NeedleInsertion::add_node(NeedleNode node) {
  if (node_of_vertex_.size() <= static_cast<std::size_t>(node.vertex)) node_of_vertex_.resize(node.vertex + 1, -1);
  node_of_vertex_[node.vertex] = static_cast<std::int32_t>(nodes_.size());
  nodes_.push_back(node);
}

int NeedleInsertion::intercept_nodes() {
  if (depth_ <= 0) return 0;
  static const PetscLogEvent event = log_event("SnedeNeedleIntercept");
  const ScopedEvent timed(event);
  const std::vector<double> u = vec_values(model_.displacement());
  const std::vector<ShaftCrossing> crossings = shaft_crossings(model_.body().mesh(), u, entry_, tip());
  const std::optional<double> body_entry = first_boundary_crossing(crossings);
  body_entry_ = body_entry && *body_entry < depth_ ? *body_entry : 0.0;
  int added = 0;
  for (const ShaftCrossing& c : crossings) {
    const VertexId v = c.near;
    added += catch_node(v, u);
  }
  // 3D: the mesh's image of the cylinder's surface, every vertex the tip has passed within r
  // of the axis (Figure 6.14).
  if (dim_ == 3) {
    const Mesh& mesh = model_.body().mesh();
    for (VertexId v = 0; v < mesh.n_points(); ++v)
      if (mesh.is_vertex(v) && across(deformed_point(mesh, u, v)) <= radius_) added += catch_node(v, u);
  }
  return added;
}

int NeedleInsertion::catch_node(VertexId v, std::span<const double> u) {
  if (static_cast<std::size_t>(v) < node_of_vertex_.size() && node_of_vertex_[v] >= 0) return 0;
  if (model_.constraints()[v].kind != ConstraintKind::free) return 0;  // held by the user
  const Point x = deformed_point(model_.body().mesh(), u, v);
  const double s = along(x);
  if (s < 0 || s > depth_) return 0;  // caught once the tip has passed it
  NeedleNode node;
  node.vertex = v;
  node.d_perp = across(x);
  node.d_needle = s;
  add_node(node);
  fix_where_it_is(v, u);  // sticks where it is
  return 1;
}

void NeedleInsertion::stick(NeedleNode& node, std::span<const double> u) {
  node.sticking = true;
  node.slip_sign = 0;
  node.friction = 0;
  fix_where_it_is(node.vertex, u);
}

void NeedleInsertion::slip(NeedleNode& node, double sign) {
  node.sticking = false;
  node.slip_sign = sign >= 0 ? 1 : -1;
  model_.slide(std::span<const VertexId>(&node.vertex, 1), std::span<const double>(direction_.data(), dim_));
}

void NeedleInsertion::release(std::size_t index) {
  const VertexId v = nodes_[index].vertex;
  model_.constraints().release(std::span<const VertexId>(&v, 1));
  erase_node(index);
}

void NeedleInsertion::erase_node(std::size_t index) {
  node_of_vertex_[nodes_[index].vertex] = -1;
  if (index + 1 != nodes_.size()) {
    nodes_[index] = nodes_.back();
    node_of_vertex_[nodes_[index].vertex] = static_cast<std::int32_t>(index);
  }
  nodes_.pop_back();
}

int NeedleInsertion::update_thresholds() {
  const std::vector<double> u = vec_values(model_.displacement());
  int released = 0;
  for (NeedleNode& node : nodes_) node.d_needle = along(deformed_point(model_.body().mesh(), u, node.vertex));
  // The node at the entry hovers about s = 0; one pulled back further than the mean spacing
  // of needle nodes has left the body's part of the shaft.
  const double spacing = nodes_.empty() ? 0.0 : (depth_ - std::min(body_entry_, depth_)) / static_cast<double>(nodes_.size());
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    const NeedleNode& node = nodes_[i];
    // Slid past the tip, or out of the body behind the entry point: off the needle.
    if (node.d_needle > depth_ || node.d_needle < -spacing) {
      release(i);
      ++released;
    }
  }
  std::vector<std::size_t> order(nodes_.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return nodes_[a].d_needle < nodes_[b].d_needle;
  });
  const double lo = std::min(body_entry_, depth_);
  if (dim_ == 3) {
    share_surface(lo);
    return released;
  }
  for (std::size_t k = 0; k < order.size(); ++k) {
    NeedleNode& node = nodes_[order[k]];
    const double begin = k == 0 ? lo : 0.5 * (nodes_[order[k - 1]].d_needle + node.d_needle);
    const double end = k + 1 == order.size() ? depth_ : 0.5 * (node.d_needle + nodes_[order[k + 1]].d_needle);
    node.share_begin = std::clamp(begin, lo, depth_);
    node.share_end = std::clamp(end, lo, depth_);
    // Distances from the tip, in deformed coordinates (Figure 6.4).
    node.dynamic_threshold = friction_.integral(depth_ - node.share_end, depth_ - node.share_begin);
    node.static_threshold = options_.static_factor * node.dynamic_threshold;
  }
  return released;
}

void NeedleInsertion::share_surface(double lo) {
  // The cylinder's surface inside the body, cut into patches (rings of surface_rings_per_h
  // per min(r, h_ref) along the shaft, surface_sectors around it); each patch belongs to the
  // needle node nearest to its centre, and adds the profile integrated over its length times
  // its arc to that node's threshold. The thresholds sum to 2πr ∫ profile exactly.
  const std::vector<double> u = vec_values(model_.displacement());
  const Mesh& mesh = model_.body().mesh();
  for (NeedleNode& node : nodes_) {
    node.dynamic_threshold = 0;
    node.share_begin = depth_;
    node.share_end = lo;
  }
  const double length = depth_ - lo;
  if (nodes_.empty() || !(length > 0)) {
    for (NeedleNode& node : nodes_) node.static_threshold = 0;
    return;
  }
  const double r = radius_;
  const double ring = std::min(r, options_.h_ref.value_or(r)) / surface_rings_per_h;
  const int n_rings = static_cast<int>(std::clamp(std::ceil(length / ring), 1.0, static_cast<double>(max_surface_rings)));
  // Two unit vectors across the shaft.
  const Point helper = std::abs(direction_[0]) < 0.9 ? Point{1, 0, 0} : Point{0, 1, 0};
  Point e1 = cross(direction_, helper);
  const double n1 = norm(e1);
  for (double& x : e1) x /= n1;
  const Point e2 = cross(direction_, e1);
  std::vector<Point> positions;
  positions.reserve(nodes_.size());
  for (const NeedleNode& node : nodes_) positions.push_back(deformed_point(mesh, u, node.vertex));
  const double arc = 2 * std::numbers::pi * r / surface_sectors;
  for (int i = 0; i < n_rings; ++i) {
    const double begin = lo + length * i / n_rings, end = lo + length * (i + 1) / n_rings;
    const double force_per_arc = friction_.integral(depth_ - end, depth_ - begin);
    const Point centre = point_at(0.5 * (begin + end));
    for (int j = 0; j < surface_sectors; ++j) {
      const double angle = 2 * std::numbers::pi * (j + 0.5) / surface_sectors;
      Point x = centre;
      for (int k = 0; k < 3; ++k) x[k] += r * (std::cos(angle) * e1[k] + std::sin(angle) * e2[k]);
      std::size_t nearest = 0;
      double best = distance(x, positions[0]);
      for (std::size_t n = 1; n < positions.size(); ++n) {
        const double d = distance(x, positions[n]);
        if (d < best) {
          best = d;
          nearest = n;
        }
      }
      NeedleNode& node = nodes_[nearest];
      node.dynamic_threshold += force_per_arc * arc;
      node.share_begin = std::min(node.share_begin, begin);
      node.share_end = std::max(node.share_end, end);
    }
  }
  for (NeedleNode& node : nodes_) {
    if (node.share_end < node.share_begin) node.share_begin = node.share_end = node.d_needle;  // no patch
    node.static_threshold = options_.static_factor * node.dynamic_threshold;
  }
}

void NeedleInsertion::apply_friction() {
  std::vector<VertexId> slipping;
  std::vector<double> forces;
  for (NeedleNode& node : nodes_) {
    if (node.sticking) continue;
    node.friction = node.slip_sign * node.dynamic_threshold;
    slipping.push_back(node.vertex);
    for (int k = 0; k < dim_; ++k) forces.push_back(node.friction * direction_[k]);
  }
  if (slipping.empty()) model_.clear_channel(options_.friction_channel);
  else model_.set_nodal_forces(options_.friction_channel, slipping, forces);
}

int NeedleInsertion::rearrange(NeedleStepResult& report) {
  static const PetscLogEvent event = log_event("SnedeNeedleRearrange");
  const ScopedEvent timed(event);
  const int released = update_thresholds();
  report.released += released;
  const std::vector<double> u = vec_values(model_.displacement());
  const std::vector<double> g = model_.potential_gradient(model_.displacement());
  int changes = released;
  for (NeedleNode& node : nodes_) {
    double g_along = 0;
    for (int k = 0; k < dim_; ++k) g_along += g[at(node.vertex, k)] * direction_[k];
    if (node.sticking) {
      // g is the force the needle exerts to hold the node; along the shaft it is friction.
      if (std::abs(g_along) > node.static_threshold) {
        slip(node, g_along);
        ++report.slipped;
        ++changes;
      }
      continue;
    }
    // Elastic (and other non-friction) force along the shaft, against the friction's pull.
    const double elastic = -g_along - node.friction;
    const double opposing = -node.slip_sign * elastic;
    if (opposing < node.dynamic_threshold - last_tolerance_) {
      stick(node, u);
      ++report.stuck;
      ++changes;
    } else if (std::abs(node.friction - node.slip_sign * node.dynamic_threshold) > last_tolerance_) {
      ++changes;  // its share moved: apply the new threshold and solve again
    }
  }
  return changes;
}

NeedleStepResult NeedleInsertion::solve_and_rearrange(NeedleStepResult report) {
  report.released += update_thresholds();
  for (;;) {
    apply_friction();
    const SolveResult result = solver_->solve();
    ++report.rearrangements;
    report.solver_iterations += result.iterations + result.linear_iterations;
    report.max_solver_iterations = std::max(report.max_solver_iterations, result.iterations + result.linear_iterations);
    last_tolerance_ = result.tolerance;
    if (!result.converged) {
      report.converged = false;
      report.reason = "SOLVE_" + result.reason;
      break;
    }
    if (rearrange(report) == 0) break;
    if (options_.solves_per_update > 0 && report.rearrangements >= options_.solves_per_update) {
      report.settled = false;  // the next update solves with the new arrangement
      break;
    }
    if (report.rearrangements >= options_.max_rearrangements) {
      report.settled = false;
      apply_friction();
      report.converged = false;
      report.reason = "DIVERGED_REARRANGEMENT_LIMIT";
      break;
    }
  }
  return report;
}

std::vector<double> NeedleInsertion::needle_forces() {
  const std::vector<double> g = model_.potential_gradient(model_.displacement());
  std::vector<double> forces;
  forces.reserve(static_cast<std::size_t>(dim_) * nodes_.size());
  for (const NeedleNode& node : nodes_) {
    double f[3] = {0, 0, 0}, g_along = 0;
    for (int k = 0; k < dim_; ++k) {
      f[k] = g[at(node.vertex, k)];
      g_along += f[k] * direction_[k];
    }
    if (!node.sticking)  // the support holds it across the shaft; friction pulls along it
      for (int k = 0; k < dim_; ++k) f[k] += (node.friction - g_along) * direction_[k];
    forces.insert(forces.end(), f, f + dim_);
  }
  return forces;
}

void NeedleInsertion::on_change(const Connectivity&, const ConnectivityChange& change) {
  const VertexId n = model_.body().mesh().n_points();
  if (node_of_vertex_.size() < static_cast<std::size_t>(n)) node_of_vertex_.resize(n, -1);
  auto node_index = [&](VertexId v) { return node_of_vertex_[v]; };
  const std::vector<double> u = vec_values(model_.displacement());
  for (const VertexEvent& event : change.vertex_events) {
    const VertexId v = event.vertex;
    if (event.kind == VertexEventKind::removed) {
      if (node_index(v) >= 0) erase_node(static_cast<std::size_t>(node_index(v)));  // the model let it go
      continue;
    }
    if (event.kind != VertexEventKind::added || event.parents.count() == 0) continue;
    std::size_t needle_parents = 0, sticking_parents = 0;
    int slip_sign = 1;
    double d_perp = 0;
    for (std::size_t i = 0; i < event.parents.count(); ++i) {
      const std::int32_t p = node_index(event.parents.vertex[i]);
      if (p < 0) continue;
      ++needle_parents;
      sticking_parents += nodes_[p].sticking;
      if (!nodes_[p].sticking) slip_sign = nodes_[p].slip_sign;
      d_perp += event.parents.weight[i] * nodes_[p].d_perp;
    }
    if (needle_parents == 0) continue;
    if (needle_parents < event.parents.count()) {
      // Between a needle node and another vertex: not on the needle; never a support.
      model_.constraints().release(std::span<const VertexId>(&v, 1));
      continue;
    }
    // On an edge of the needle's representation: it joins the needle. All parents sticking:
    // the model has already fixed it at the interpolated anchor.
    NeedleNode node;
    node.vertex = v;
    node.d_perp = d_perp;
    node.d_needle = along(deformed_point(model_.body().mesh(), u, v));
    node.sticking = sticking_parents == event.parents.count();
    add_node(node);
    if (!node.sticking) slip(nodes_.back(), slip_sign);
  }
}

}  // namespace snede
