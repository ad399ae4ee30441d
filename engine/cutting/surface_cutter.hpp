// Cutting a triangulated surface in 3D with a line-segment scalpel (§5.3.1, single incision),
// on a bare surface mesh or a membrane body that may be deformed: the scalpel moves in
// deformed coordinates x = X + u and the mesh is edited in the reference configuration.
//
// The scalpel is a segment whose ends move with constant velocity between samples. Each move
// is taken in steps no longer than d_max (Figure 5.11: the distance between the scalpel's line
// and the lines of the edges opposite the active node, at least ε_edge/4). In each step:
//  * outside, the swept scalpel (equation (5.1)) crossing a boundary edge enters there
//    (Figure 5.12a); otherwise the scalpel piercing a triangle enters with its tip there
//    (Figure 5.12b). The candidate triangles come from a uniform grid (TriangleGrid). The
//    incision begins when the scalpel meets the entry node's star more than ε_entry away: a node
//    is inserted there and the edge to it dissected — for a tip entry the edge is first split,
//    so that the slit has an interior node and opens;
//  * cutting, the scalpel is intersected with the active triangles and the active node moved
//    to the intersection. When it misses them, the edge opposite the active node that the
//    swept scalpel crosses first is flipped away (refused flips, Figure 5.9, remove its nearer
//    interior end instead, Figure 5.10) after the node has moved 0.6 of the way towards it;
//    a boundary edge there is the exit (Figure 5.7);
//  * the active triangles are flipped to the unfolded Delaunay criterion (is_locally_delaunay
//    on a surface), interior nodes within ε_edge of the active node removed, and the incision
//    split (Figure 5.5) where its cut edges, unfolded about the active node, fail the
//    empty-circle test: new nodes on both lips where the unfolded line through the opposite
//    nodes crosses them.
// Departures from the thesis: the new incision nodes go on the cut edges (a chord of the
// path), not onto the path itself; one incision at a time (§5.3.2's multiple and branching
// incisions are not handled: the scalpel drives one active node, and a second piercing of the
// surface is ignored while it cuts).
#pragma once

#include <optional>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cutting/delaunay_cutter.hpp"
#include "cutting/sweep_triangle.hpp"
#include "cutting/triangle_grid.hpp"
#include "solve/model.hpp"

namespace snede {

struct SurfaceCutterOptions {
  // Reference distances; 0 means the thesis's defaults from the mean edge length h̄ (§5.4):
  // ε_edge = h̄/3, ε_entry = ε_exit = h̄/6.
  double eps_edge = 0;
  double eps_entry = 0;
  double eps_exit = 0;
};

class SurfaceCutter {
 public:
  // Cuts `mesh` (triangles in 3D). With a model (whose body is on this mesh) the scalpel moves
  // in deformed coordinates. Throws std::invalid_argument for another kind of mesh, or
  // negative or non-finite thresholds.
  SurfaceCutter(Mesh& mesh, Model* model, SurfaceCutterOptions options);

  // Moves the scalpel to `segment` (6 numbers: its two ends, deformed coordinates); the first
  // move after construction or lift() only places it. Throws std::invalid_argument, before
  // changing anything, for non-finite coordinates or coinciding ends. The report's fields
  // mean what they mean for the 2D cutter.
  PlanarCutReport move(std::span<const double> segment);
  void lift();

  VertexId active_node() const { return phase_ == Phase::cutting ? active_ : -1; }
  bool cutting() const { return phase_ == Phase::cutting; }
  std::vector<VertexId> incision_edges() const;
  const SurfaceCutterOptions& options() const { return options_; }

 private:
  enum class Phase { outside, entering, cutting };
  struct Segment {
    Point3 head, tail;
  };
  struct Wedge {  // triangle (b, y, z) of b's star, in its orientation
    ElementId element;
    VertexId y, z;
  };
  struct StarHit {  // the scalpel meets triangle (b, y, z) at these barycentric weights
    Wedge wedge;
    std::array<double, 3> weights;
  };
  struct LinkCrossing {  // the swept scalpel meets link edge (y, z) at y + mu (z − y)
    Wedge wedge;
    double time, mu;
  };

  Point3 reference(VertexId v) const;
  Point3 deformed(VertexId v) const;
  // Records where a vertex just added or moved with these parents is in deformed space.
  void follow(VertexId v, const VertexParents& parents);
  std::vector<Wedge> wedges(VertexId b) const;
  bool on_boundary(VertexId v) const;
  // Whether every triangle of v's star, with v moved to x, turns its normal by less than 60°
  // (those with vertex merging_into, which a collapse into it removes, aside).
  bool keeps_facing(VertexId v, const Point3& x, VertexId merging_into = -1) const;
  bool is_boundary_edge(ElementId triangle, VertexId opposite) const;
  Point3 reference_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights) const;

  std::optional<StarHit> hit_in_star(VertexId b, const Segment& scalpel) const;
  std::optional<LinkCrossing> first_link_crossing(VertexId b, const Segment& from, const Segment& to) const;
  double step_limit(VertexId b, const Segment& scalpel) const;  // d_max, Figure 5.11
  std::vector<ElementId> triangles_near(const Segment& from, const Segment& to);
  bool touches_surface(const Segment& scalpel);

  void sweep(const Segment& from, const Segment& to, PlanarCutReport& report);
  void look_for_entry(const Segment& from, const Segment& to, PlanarCutReport& report);
  void begin_incision(const Segment& scalpel, PlanarCutReport& report);
  void advance(const Segment& from, const Segment& to, PlanarCutReport& report);
  // Moves the active node to the point with `weights` in its star triangle, or part of the way.
  bool move_active_to(const Wedge& w, std::array<double, 3> weights);
  // A new vertex at `weights` in triangle (b, y, z), on a side when a weight is (nearly) 0.
  VertexId insert_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights, PlanarCutReport& report);
  VertexId split(VertexId a, VertexId b, double t);
  bool flip(VertexId p, VertexId q, PlanarCutReport& report);
  bool remove_node(VertexId v, PlanarCutReport& report);
  void remesh_around(VertexId b, PlanarCutReport& report);
  void split_incision(PlanarCutReport& report);
  void exit_through(VertexId y, VertexId z, double mu, PlanarCutReport& report);
  std::vector<VertexId> dissect_edges(const std::vector<std::array<VertexId, 2>>& edges);
  void legalize(PlanarCutReport& report);

  Mesh& mesh_;
  Model* model_;
  SurfaceCutterOptions options_;
  Phase phase_ = Phase::outside;
  VertexId active_ = -1;
  bool tip_entry_ = false;
  bool left_surface_ = true;  // after an exit, no entry until the scalpel has left the surface
  std::optional<Segment> scalpel_;
  std::vector<double> displacement_;                // u at the start of the move (3 per point)
  std::unordered_map<VertexId, Point3> moved_;      // deformed positions of vertices edited since
  TriangleGrid grid_;
  std::optional<std::uint64_t> grid_revision_;
  bool grid_stale_ = true;
  std::unordered_set<VertexId> incision_vertices_;
  std::vector<VertexId> touched_;
};

}  // namespace snede
