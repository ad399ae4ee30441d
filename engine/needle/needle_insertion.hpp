// Needle insertion into a plane-stress sheet with stick-slip friction (§6.3–§6.7).
//
// The needle is a rigid straight line in space: it enters at `entry` along `direction`, and
// its tip is at entry + depth·direction. When the tip enters an element through an edge, the
// edge's end closest to the shaft becomes a *needle node* (§6.4); the node keeps its offset
// d_perp from the shaft and has a position d_needle along it. A needle node either sticks
// (its displacement is prescribed: it moves with the needle) or slips (it slides along a line
// parallel to the shaft, loaded by the dynamic friction force in the model's "friction"
// channel). Friction thresholds come from the friction profile, integrated over the node's
// share of the shaft (half-way to its neighbours along the shaft, clipped to the part inside
// the body); the static threshold is static_factor times the dynamic one.
//
// One update (advance) is the interaction loop of §6.7: move the needle (in halves where the
// move would invert elements of a material that forbids it), refine to h_ref
// around the tip (§6.5, one batched change), add intercepted nodes, then solve and rearrange
// (§6.3.2) until no node changes state: a sticking node whose reaction along the shaft
// exceeds its static threshold slips; a slipping node whose elastic force along the shaft
// has fallen below its dynamic threshold (by more than the solver's tolerance) sticks where
// it is; nodes that slid past the tip, or back out of the body behind the entry point by more
// than the mean spacing of needle nodes, are released.
//
// It watches the mesh: a vertex added by refinement between needle nodes joins the needle.
#pragma once

#include <petscvec.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "needle/deformed_queries.hpp"
#include "needle/friction_profile.hpp"
#include "solve/static_solver.hpp"
#include "topology/bisection.hpp"

namespace snede {

struct NeedleNode {
  VertexId vertex = no_id;
  bool sticking = true;
  double d_perp = 0;           // signed offset from the shaft (along the shaft's normal), held
  double d_needle = 0;         // position along the shaft from the entry point (deformed)
  double share_begin = 0, share_end = 0;  // the node's share of the shaft, along it
  double dynamic_threshold = 0;
  double static_threshold = 0;
  int slip_sign = 0;           // +1/−1: the direction (along the shaft) friction pulls a slipping node
  double friction = 0;         // signed force along the shaft applied while slipping
};

struct NeedleOptions {
  double static_factor = 2.0;
  std::optional<double> h_ref;  // refine around the tip down to this edge length
  int max_rearrangements = 200; // per update; exceeding it is reported, not hidden
  // The thesis's haptic loop (§6.7): at most this many solves per update (0: until settled);
  // rearrangements still pending are carried into the next update, which is not a failure.
  int solves_per_update = 0;
  // Start each update's solve from the last state plus the last update's displacement change
  // per unit of needle travel (a linear predictor) instead of from the last state.
  bool extrapolate = false;
  std::string friction_channel = "friction";
};

struct NeedleStepReport {
  int rearrangements = 0;        // solves in this update (each followed by a rearrangement)
  int slipped = 0, stuck = 0, released = 0, intercepted = 0;  // state changes in this update
  int cells_split = 0;
  int solver_iterations = 0;     // total over the solves
  int max_solver_iterations = 0;
  bool converged = true;         // every solve converged and the rearrangements settled
  bool settled = true;           // no needle node changes state at the final solution
  std::string reason = "CONVERGED";
  double seconds = 0;
};

class NeedleInsertion : public ConnectivityWatcher {
 public:
  // The model must be a 2D (plane-stress) model. bisection: the mesh's bisection (needed
  // when h_ref is set; may be null otherwise). Throws std::invalid_argument for a zero
  // direction, a needle whose line from entry misses the body, a 3D model, or bad options.
  NeedleInsertion(Model& model, Bisection* bisection, const Point2& entry, const Point2& direction,
                  FrictionProfile friction, NeedleOptions options, StaticOptions solver_options);
  ~NeedleInsertion() override;
  NeedleInsertion(const NeedleInsertion&) = delete;
  NeedleInsertion& operator=(const NeedleInsertion&) = delete;

  // One update of §6.7 with the needle moved `distance` ≥ 0 further in.
  NeedleStepReport advance(double distance);
  // Solve and rearrange at the current needle position, without moving it.
  NeedleStepReport settle();

  const std::vector<NeedleNode>& needle_nodes() const { return nodes_; }
  Point2 entry() const { return entry_; }
  Point2 direction() const { return direction_; }
  double depth() const { return depth_; }
  Point2 tip() const { return {entry_[0] + depth_ * direction_[0], entry_[1] + depth_ * direction_[1]}; }
  // Force the needle exerts on the body at each needle node: support reaction plus friction,
  // (n_needle_nodes, 2), in the order of needle_nodes().
  std::vector<double> needle_forces();
  const FrictionProfile& friction_profile() const { return friction_; }
  const NeedleOptions& options() const { return options_; }
  StaticSolver& solver() { return *solver_; }

  void init(const Connectivity&) override {}
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;

 private:
  double along(const Point2& x) const;   // position along the shaft from the entry point
  double across(const Point2& x) const;  // signed offset from the shaft
  void refine_at_tip();
  int intercept_nodes();
  void stick(NeedleNode& node, std::span<const double> u);
  // Slides along the shaft from where it is; friction pulls it in direction sign (±1).
  void slip(NeedleNode& node, double sign);
  // Positions along the shaft, shares, thresholds; releases nodes off the needle. Returns the
  // number released.
  int update_thresholds();
  void apply_friction();
  // One rearrangement pass after a solve: the number of nodes whose state changed.
  int rearrange(NeedleStepReport& report);
  NeedleStepReport solve_and_rearrange(NeedleStepReport report);
  // Shifts the depth and the sticking nodes' prescribed displacements.
  void move_needle(double distance);
  // advance without timing; halves the move (up to max_halvings times) where it would start
  // the solve from inverted elements.
  NeedleStepReport advance_in_steps(double distance, int halvings);
  static NeedleStepReport merged(const NeedleStepReport& first, const NeedleStepReport& second);
  static constexpr int max_halvings = 12;
  // Frees the vertex's constraint and drops the node; erase_node only drops it.
  void release(std::size_t index);
  void erase_node(std::size_t index);
  void add_node(NeedleNode node);

  Model& model_;
  Bisection* bisection_;
  std::vector<std::int32_t> node_of_vertex_;  // index into nodes_, or -1
  Point2 entry_, direction_, normal_;
  double depth_ = 0;
  double body_entry_ = 0;  // where the shaft enters the body, along it
  FrictionProfile friction_;
  NeedleOptions options_;
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
