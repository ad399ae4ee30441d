// Needle insertion with stick-slip friction (§6.3–§6.7): into a plane-stress sheet (2D), or
// into a solid as a rigid cylinder of radius r (3D, §6.9 and Figure 6.14).
//
// The needle's axis is a straight line in space: it enters at `entry` along `direction`, and
// its tip is at entry + depth·direction. When the tip enters an element through an edge (2D)
// or a face (3D), that edge's or face's vertex closest to the axis becomes a *needle node*
// (§6.4). In 3D every vertex the tip has passed that lies within r of the axis joins the
// needle too: the needle nodes are the mesh's jagged image of the cylinder's surface. A node
// keeps its offset d_perp from the axis (signed in 2D, a distance in 3D) and has a position
// d_needle along it. A needle node either sticks
// (its displacement is prescribed: it moves with the needle) or slips (it slides along a line
// parallel to the shaft, loaded by the dynamic friction force in the model's "friction"
// channel). Friction thresholds come from the friction profile, integrated over the node's
// share of the shaft (half-way to its neighbours along the shaft, clipped to the part inside
// the body). In 3D the profile is a force per unit of shaft surface, and a node's share is
// the part of the cylinder's surface (inside the body) nearer to it than to any other needle
// node; a node inside the needle that no part of the surface is nearest to has no friction.
// The static threshold is static_factor times the dynamic one.
//
// One update (advance) is the interaction loop of §6.7: move the needle (in halves where the
// move would invert elements of a material that forbids it), refine to h_ref
// around the tip (§6.5; in 3D along the shaft within r of the axis; one batched change), add
// intercepted nodes, then solve and rearrange
// (§6.3.2) until no node changes state: a sticking node whose reaction along the shaft
// exceeds its static threshold slips; a slipping node whose elastic force along the shaft
// has fallen below its dynamic threshold (by more than the solver's tolerance) sticks where
// it is; nodes that slid past the tip, or back out of the body behind the entry point by more
// than the mean spacing of needle nodes, are released.
//
// It watches the mesh: a vertex added by refinement between needle nodes joins the needle.
#pragma once

#include <petscvec.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "needle/deformed_queries.hpp"
#include "needle/friction_profile.hpp"
#include "solvers/static_solver.hpp"
#include "topology/bisection.hpp"

namespace snede {

struct NeedleNode {
  VertexId vertex = no_id;
  bool sticking = true;
  double d_perp = 0;           // offset from the shaft: signed along its normal (2D), distance (3D)
  double d_needle = 0;         // position along the shaft from the entry point (deformed)
  double share_begin = 0, share_end = 0;  // the node's share of the shaft, along it
  double dynamic_threshold = 0;
  double static_threshold = 0;
  int slip_sign = 0;           // +1/−1: the direction (along the shaft) friction pulls a slipping node
  double friction = 0;         // signed force along the shaft applied while slipping
};

struct NeedleOptions {
  double static_factor = 2.0;
  std::optional<double> h_ref;  // refine around the tip (3D: and along the shaft) to this edge length
  // 3D: the needle's radius (> 0; unset: default_radius). 2D: unset (the needle is a line).
  std::optional<double> radius;
  static constexpr double default_radius = 1e-3;
  int max_rearrangements = 200; // per update; exceeding it is reported, not hidden
  // The thesis's haptic loop (§6.7): at most this many solves per update (0: until settled);
  // rearrangements still pending are carried into the next update, which is not a failure.
  int solves_per_update = 0;
  // Start each update's solve from the last state plus the last update's displacement change
  // per unit of needle travel (a linear predictor) instead of from the last state.
  bool extrapolate = false;
  // A move that would invert elements is first carried into the tissue over this many rings of
  // vertices around the sticking nodes (move_extension.hpp); halved only if that is not
  // enough. 0: halve at once (the behaviour before issue 50).
  int extension_rings = 3;
  std::string friction_channel = "friction";

  // std::invalid_argument naming the first setting out of range (what needs the body, a
  // radius in 2D, is the constructor's).
  void validate() const;

  // Every field with its name: the one list that bindings and printing read.
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("static_factor", &NeedleOptions::static_factor);
    visit("h_ref", &NeedleOptions::h_ref);
    visit("radius", &NeedleOptions::radius);
    visit("max_rearrangements", &NeedleOptions::max_rearrangements);
    visit("solves_per_update", &NeedleOptions::solves_per_update);
    visit("extrapolate", &NeedleOptions::extrapolate);
    visit("extension_rings", &NeedleOptions::extension_rings);
    visit("friction_channel", &NeedleOptions::friction_channel);
  }
};

struct NeedleStepResult {
  int rearrangements = 0;        // solves in this update (each followed by a rearrangement)
  int slipped = 0, stuck = 0, released = 0, intercepted = 0;  // state changes in this update
  int cells_split = 0;
  int extensions = 0;            // moves carried into the tissue (NeedleOptions::extension_rings)
  int halvings = 0;              // moves halved because they would start the solve inverted
  int solver_iterations = 0;     // total over the solves
  int max_solver_iterations = 0;
  bool converged = true;         // every solve converged and the rearrangements settled
  bool settled = true;           // no needle node changes state at the final solution
  std::string reason = "CONVERGED";
  double seconds = 0;

  // Every field with its name: the one list that bindings and printing read.
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("rearrangements", &NeedleStepResult::rearrangements);
    visit("solver_iterations", &NeedleStepResult::solver_iterations);
    visit("max_solver_iterations", &NeedleStepResult::max_solver_iterations);
    visit("slipped", &NeedleStepResult::slipped);
    visit("stuck", &NeedleStepResult::stuck);
    visit("released", &NeedleStepResult::released);
    visit("intercepted", &NeedleStepResult::intercepted);
    visit("cells_split", &NeedleStepResult::cells_split);
    visit("extensions", &NeedleStepResult::extensions);
    visit("halvings", &NeedleStepResult::halvings);
    visit("converged", &NeedleStepResult::converged);
    visit("settled", &NeedleStepResult::settled);
    visit("reason", &NeedleStepResult::reason);
    visit("seconds", &NeedleStepResult::seconds);
  }
};

class NeedleInsertion : public ConnectivityWatcher {
 public:
  // The model is a 2D (plane-stress) or 3D (tetrahedral) one; entry and direction have its
  // dimension (the third component is ignored in 2D). bisection: the mesh's bisection (needed
  // when h_ref is set; may be null otherwise). Throws std::invalid_argument for a zero
  // direction, a needle whose line from entry misses the body, a surface mesh, a radius given
  // in 2D, or bad options.
  NeedleInsertion(Model& model, Bisection* bisection, const Point& entry, const Point& direction,
                  FrictionProfile friction, NeedleOptions options, StaticOptions solver_options);
  // The static solver a needle relaxes with unless told otherwise: linear CG to rtol 1e-3 (the
  // thesis's ε of §6.8), a round-off floor of 1e-8 (the loop's corrections are small against
  // the accumulated state) and the options prefix "needle_".
  static StaticOptions default_solver_options();
  // Where "auto" starts multigrid for a 2D needle solved by linear CG (the constructor says why).
  static constexpr std::int64_t planar_linear_multigrid_from_cells = 10000;
  ~NeedleInsertion() override;
  NeedleInsertion(const NeedleInsertion&) = delete;
  NeedleInsertion& operator=(const NeedleInsertion&) = delete;

  // One update of §6.7 with the needle moved `distance` ≥ 0 further in.
  NeedleStepResult advance(double distance);
  // Solve and rearrange at the current needle position, without moving it.
  NeedleStepResult settle();

  const std::vector<NeedleNode>& needle_nodes() const { return nodes_; }
  int dim() const { return dim_; }
  Point entry() const { return entry_; }
  Point direction() const { return direction_; }
  double depth() const { return depth_; }
  Point tip() const { return point_at(depth_); }
  // How far from the entry point the shaft's line first meets the deformed body: 0 when the
  // entry point is inside it. Throws std::invalid_argument if it no longer meets the body.
  double surface_depth() const;
  // Force the needle exerts on the body at each needle node: support reaction plus friction,
  // (n_needle_nodes, dim), in the order of needle_nodes().
  std::vector<double> needle_forces();
  const FrictionProfile& friction_profile() const { return friction_; }
  const NeedleOptions& options() const { return options_; }
  double radius() const { return radius_; }  // 0 in 2D
  StaticSolver& solver() { return *solver_; }

  void init(const Connectivity&) override {}
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;

 private:
  Point point_at(double s) const;       // the point s along the axis from the entry point
  // Where the line from the entry point first meets the deformed body (0 from inside), along
  // it; nothing if it misses. O(n): scans the mesh.
  std::optional<double> first_contact() const;
  double along(const Point& x) const;   // position along the shaft from the entry point
  double across(const Point& x) const;  // offset from the shaft (signed in 2D)
  // Component i of vertex v's entry in a nodal array (n_points, dim).
  std::size_t at(VertexId v, int i = 0) const { return static_cast<std::size_t>(v) * dim_ + i; }
  // Fixes v at its current displacement (u: the state).
  void fix_where_it_is(VertexId v, std::span<const double> u);
  void refine_at_tip();
  // Carries a move of the sticking nodes into the vertices around them (move_extension.hpp).
  void extend_move(double distance);
  // Whether the moved state may start a solve: admissible to the model, and no element of a
  // material that forbids inversion flattened to det F ≤ collapse_floor.
  bool move_admissible() const;
  static constexpr double collapse_floor = 1e-6;
  int intercept_nodes();
  // Makes v a sticking needle node if it is free, not one already and the tip has passed it.
  int catch_node(VertexId v, std::span<const double> u);
  void stick(NeedleNode& node, std::span<const double> u);
  // Slides along the shaft from where it is; friction pulls it in direction sign (±1).
  void slip(NeedleNode& node, double sign);
  // Positions along the shaft, shares, thresholds; releases nodes off the needle. Returns the
  // number released.
  int update_thresholds();
  // 3D: each node's share of the shaft's surface inside the body (from lo to the tip), and
  // its thresholds from it.
  void share_surface(double lo);
  static constexpr int surface_sectors = 16;
  static constexpr int surface_rings_per_h = 2;
  static constexpr int max_surface_rings = 4096;
  void apply_friction();
  // One rearrangement pass after a solve: the number of nodes whose state changed.
  int rearrange(NeedleStepResult& report);
  NeedleStepResult solve_and_rearrange(NeedleStepResult report);
  // Shifts the depth and the sticking nodes' prescribed displacements.
  void move_needle(double distance);
  // advance without timing; halves the move (up to max_halvings times) where it would start
  // the solve from inverted elements.
  NeedleStepResult advance_in_steps(double distance, int halvings);
  static NeedleStepResult merged(const NeedleStepResult& first, const NeedleStepResult& second);
  static constexpr int max_halvings = 12;
  // Frees the vertex's constraint and drops the node; erase_node only drops it.
  void release(std::size_t index);
  void erase_node(std::size_t index);
  void add_node(NeedleNode node);

  Model& model_;
  Bisection* bisection_;
  std::vector<std::int32_t> node_of_vertex_;  // index into nodes_, or -1
  int dim_;
  Point entry_, direction_, normal_;  // normal_: 2D only
  double depth_ = 0;
  double body_entry_ = 0;  // where the shaft enters the body, along it
  std::optional<Point> refined_from_;  // 3D: where the shaft's refinement continues (reference)
  FrictionProfile friction_;
  NeedleOptions options_;
  double radius_ = 0;  // options_.radius resolved: 0 in 2D (a line), its default in 3D
  std::unique_ptr<StaticSolver> solver_;
  std::vector<NeedleNode> nodes_;
  double last_tolerance_ = 0;
  // Predictor (a warm start better than the last state): the displacement change per unit of
  // needle travel in the last update, carried through mesh changes like the state.
  VecHandle rate_;
  VecHandle start_;  // the state at the start of the current update
  bool have_rate_ = false;
  void predict(double distance);
  void record_rate(double distance);
  void create_predictor_vectors();
};

}  // namespace snede
