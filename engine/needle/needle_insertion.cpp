#include "needle/needle_insertion.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "core/petsc_util.hpp"
#include "topology/refine_around.hpp"

namespace snede {
namespace {

std::string point_text(const Point2& x) {
  std::ostringstream text;
  text << "(" << x[0] << ", " << x[1] << ")";
  return text.str();
}

}  // namespace

NeedleInsertion::NeedleInsertion(Model& model, Bisection* bisection, const Point2& entry, const Point2& direction,
                                 FrictionProfile friction, NeedleOptions options, StaticOptions solver_options)
    : model_(model), bisection_(bisection), entry_(entry), friction_(std::move(friction)), options_(std::move(options)) {
  if (model_.dim() != 2 || model_.body().mesh().is_surface())
    throw std::invalid_argument("needle insertion is implemented for 2D plane-stress bodies; this body is " +
                                std::to_string(model_.dim()) + "-D");
  if (!std::isfinite(entry[0]) || !std::isfinite(entry[1]))
    throw std::invalid_argument("needle entry must be finite, got " + point_text(entry));
  const double norm = std::hypot(direction[0], direction[1]);
  if (!(norm > 0) || !std::isfinite(norm))
    throw std::invalid_argument("needle direction must be non-zero and finite, got " + point_text(direction));
  direction_ = {direction[0] / norm, direction[1] / norm};
  normal_ = {-direction_[1], direction_[0]};
  if (!(options_.static_factor >= 1.0) || !std::isfinite(options_.static_factor))
    throw std::invalid_argument("static_factor must be at least 1 (static friction ≥ dynamic), got " +
                                std::to_string(options_.static_factor));
  if (options_.solves_per_update < 0)
    throw std::invalid_argument("solves_per_update must be 0 (until settled) or positive, got " +
                                std::to_string(options_.solves_per_update));
  if (options_.max_rearrangements < 1)
    throw std::invalid_argument("max_rearrangements must be at least 1, got " +
                                std::to_string(options_.max_rearrangements));
  if (options_.h_ref) {
    if (!(*options_.h_ref > 0) || !std::isfinite(*options_.h_ref))
      throw std::invalid_argument("h_ref must be positive and finite, got " + std::to_string(*options_.h_ref));
    if (!bisection_) throw std::invalid_argument("h_ref needs the mesh's bisection");
  }
  // The needle's line from the entry point must meet the body.
  const Mesh& mesh = model_.body().mesh();
  const std::vector<double> u = vec_values(model_.displacement());
  double reach = 0;
  for (VertexId v = 0; v < mesh.n_points(); ++v) {
    if (!mesh.is_vertex(v)) continue;
    const Point2 x = deformed_point(mesh, u, v);
    reach = std::max(reach, std::hypot(x[0] - entry_[0], x[1] - entry_[1]));
  }
  const Point2 far{entry_[0] + 2 * reach * direction_[0], entry_[1] + 2 * reach * direction_[1]};
  if (shaft_crossings(mesh, u, entry_, far).empty() && !reference_position(mesh, u, entry_))
    throw std::invalid_argument("the needle from entry " + point_text(entry_) + " along " + point_text(direction_) +
                                " never meets the body");
  solver_ = std::make_unique<StaticSolver>(model_, std::move(solver_options));
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

double NeedleInsertion::along(const Point2& x) const {
  return (x[0] - entry_[0]) * direction_[0] + (x[1] - entry_[1]) * direction_[1];
}

double NeedleInsertion::across(const Point2& x) const {
  return (x[0] - entry_[0]) * normal_[0] + (x[1] - entry_[1]) * normal_[1];
}

NeedleStepReport NeedleInsertion::advance(double distance) {
  if (!(distance >= 0) || !std::isfinite(distance))
    throw std::invalid_argument("the needle advances by a non-negative, finite distance; got " +
                                std::to_string(distance));
  const double start = wall_seconds();
  NeedleStepReport report = advance_in_steps(distance, 0);
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
    anchors.push_back(c.anchor[0] + distance * direction_[0]);
    anchors.push_back(c.anchor[1] + distance * direction_[1]);
  }
  if (!moved.empty()) model_.fix(moved, anchors);
}

NeedleStepReport NeedleInsertion::advance_in_steps(double distance, int halvings) {
  move_needle(distance);
  // A move that drags sticking nodes across their neighbours would start the solve from
  // inverted elements, which a material forbidding inversion cannot relax: move in halves.
  if (distance > 0 && halvings < max_halvings && !model_.admissible(model_.displacement())) {
    move_needle(-distance);
    NeedleStepReport first = advance_in_steps(0.5 * distance, halvings + 1);
    if (!first.converged) return first;
    return merged(first, advance_in_steps(0.5 * distance, halvings + 1));
  }
  NeedleStepReport report;
  predict(distance);
  const std::size_t cells_before = model_.body().mesh().n_cells();
  refine_at_tip();
  report.cells_split = static_cast<int>(model_.body().mesh().n_cells() - cells_before);
  report.intercepted = intercept_nodes();
  report = solve_and_rearrange(report);
  if (report.converged) record_rate(distance);
  return report;
}

NeedleStepReport NeedleInsertion::merged(const NeedleStepReport& a, const NeedleStepReport& b) {
  NeedleStepReport m = b;
  m.rearrangements += a.rearrangements;
  m.slipped += a.slipped;
  m.stuck += a.stuck;
  m.released += a.released;
  m.intercepted += a.intercepted;
  m.cells_split += a.cells_split;
  m.solver_iterations += a.solver_iterations;
  m.max_solver_iterations = std::max(a.max_solver_iterations, b.max_solver_iterations);
  m.settled = b.settled;
  return m;
}

NeedleStepReport NeedleInsertion::settle() {
  const double start = wall_seconds();
  NeedleStepReport report;
  report.intercepted = intercept_nodes();
  report = solve_and_rearrange(report);
  report.seconds = wall_seconds() - start;
  return report;
}

void NeedleInsertion::refine_at_tip() {
  if (!options_.h_ref || depth_ <= 0) return;
  const std::vector<double> u = vec_values(model_.displacement());
  // refine_around works in the reference configuration: refine around the material point
  // under the deformed tip.
  const std::optional<Point2> X = reference_position(model_.body().mesh(), u, tip());
  if (!X) return;  // the tip is outside the body
  refine_around(*bisection_, std::span<const double>(X->data(), 2), *options_.h_ref);
}

void NeedleInsertion::add_node(NeedleNode node) {
  if (node_of_vertex_.size() <= static_cast<std::size_t>(node.vertex)) node_of_vertex_.resize(node.vertex + 1, -1);
  node_of_vertex_[node.vertex] = static_cast<std::int32_t>(nodes_.size());
  nodes_.push_back(node);
}

int NeedleInsertion::intercept_nodes() {
  if (depth_ <= 0) return 0;
  const std::vector<double> u = vec_values(model_.displacement());
  const std::vector<ShaftCrossing> crossings = shaft_crossings(model_.body().mesh(), u, entry_, tip());
  double body_entry = depth_;
  bool on_boundary = false;
  for (const ShaftCrossing& c : crossings)
    if (c.on_boundary && c.s < body_entry) {
      body_entry = c.s;
      on_boundary = true;
    }
  body_entry_ = on_boundary ? body_entry : 0.0;
  int added = 0;
  for (const ShaftCrossing& c : crossings) {
    const VertexId v = c.near;
    if (static_cast<std::size_t>(v) < node_of_vertex_.size() && node_of_vertex_[v] >= 0) continue;
    if (model_.constraints()[v].kind != ConstraintKind::free) continue;  // held by the user
    const Point2 x = deformed_point(model_.body().mesh(), u, v);
    const double s = along(x);
    if (s < 0 || s > depth_) continue;  // caught once the tip has passed it
    NeedleNode node;
    node.vertex = v;
    node.d_perp = across(x);
    node.d_needle = s;
    add_node(node);
    const double anchor[2] = {u[2 * static_cast<std::size_t>(v)], u[2 * static_cast<std::size_t>(v) + 1]};
    model_.fix(std::span<const VertexId>(&v, 1), anchor);  // sticks where it is
    ++added;
  }
  return added;
}

void NeedleInsertion::stick(NeedleNode& node, std::span<const double> u) {
  node.sticking = true;
  node.slip_sign = 0;
  node.friction = 0;
  const std::size_t i = 2 * static_cast<std::size_t>(node.vertex);
  const double anchor[2] = {u[i], u[i + 1]};
  model_.fix(std::span<const VertexId>(&node.vertex, 1), anchor);
}

void NeedleInsertion::slip(NeedleNode& node, double sign) {
  node.sticking = false;
  node.slip_sign = sign >= 0 ? 1 : -1;
  model_.slide(std::span<const VertexId>(&node.vertex, 1), direction_);
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

void NeedleInsertion::apply_friction() {
  std::vector<VertexId> slipping;
  std::vector<double> forces;
  for (NeedleNode& node : nodes_) {
    if (node.sticking) continue;
    node.friction = node.slip_sign * node.dynamic_threshold;
    slipping.push_back(node.vertex);
    forces.push_back(node.friction * direction_[0]);
    forces.push_back(node.friction * direction_[1]);
  }
  if (slipping.empty()) model_.clear_channel(options_.friction_channel);
  else model_.set_nodal_forces(options_.friction_channel, slipping, forces);
}

int NeedleInsertion::rearrange(NeedleStepReport& report) {
  const int released = update_thresholds();
  report.released += released;
  const std::vector<double> u = vec_values(model_.displacement());
  const std::vector<double> g = model_.potential_gradient(model_.displacement());
  int changes = released;
  for (NeedleNode& node : nodes_) {
    const std::size_t i = 2 * static_cast<std::size_t>(node.vertex);
    const double g_along = g[i] * direction_[0] + g[i + 1] * direction_[1];
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

NeedleStepReport NeedleInsertion::solve_and_rearrange(NeedleStepReport report) {
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
  forces.reserve(2 * nodes_.size());
  for (const NeedleNode& node : nodes_) {
    const std::size_t i = 2 * static_cast<std::size_t>(node.vertex);
    double f[2] = {g[i], g[i + 1]};
    if (!node.sticking) {  // the support holds it across the shaft; friction pulls along it
      const double g_along = f[0] * direction_[0] + f[1] * direction_[1];
      for (int k = 0; k < 2; ++k) f[k] += (node.friction - g_along) * direction_[k];
    }
    forces.push_back(f[0]);
    forces.push_back(f[1]);
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
