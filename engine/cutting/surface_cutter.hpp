// Cutting a triangulated surface in 3D with a line-segment scalpel (§5.3), on a bare surface
// mesh or a membrane body that may be deformed: the scalpel moves in deformed coordinates
// x = X + u and the mesh is edited in the reference configuration.
//
// The scalpel is a segment whose ends move with constant velocity between samples. A move is
// taken in steps no longer than d_max of every active node (Figure 5.11: the distance between
// the scalpel's line and the lines of the edges opposite the active node, at least ε_edge/8),
// and cut short where the scalpel first touches the surface somewhere new. Each step:
//  * every incision follows the scalpel (§5.3.1). An entry node waits until the scalpel has
//    moved ε_entry from it, then the edge to a new active node is dissected (for an entry
//    inside the surface the edge is first split, so that the slit has an interior node and
//    opens). A cutting incision's active node moves to where the scalpel meets its triangles;
//    when the scalpel misses them, the edge opposite the active node that the swept scalpel
//    crosses first is flipped away (refused flips, Figure 5.9, remove its nearer interior end
//    instead, Figure 5.10) after the node has moved 0.6 of the way towards it (a node a
//    refused move left behind is swept to from where it is). A star triangle that would fold
//    on the way is cleared the same way, or, left behind, taken from the star by a flip of a
//    spoke. Then the active triangles are flipped to the unfolded Delaunay criterion, interior
//    nodes within ε_edge of the active node removed, and the incision split (Figure 5.5) where
//    its cut edges, unfolded about the active node, fail the empty-circle test;
//  * where the surface has a crease (neighbouring triangles turned by 45° or more: a box's
//    edge, a coarse ridge) no flip, node removal or node move crosses it, since each would
//    make a chord through the body; the incision puts a node on the scalpel's path where the
//    swept scalpel crosses the crease (§5.3.1's nodes on the path), and a node on a crease
//    stays there: its incision goes on from a new node at the scalpel's hit once that is
//    ε_edge/4 away (no shorter cut edge);
//  * the scalpel meeting an active node's triangles in several places far apart branches the
//    incision (Figure 5.14): a new active node at each place, the edges to them dissected;
//  * an incision ends where its active node reaches an edge it may not flip (Figure 5.13,
//    annihilation): a boundary edge (the exit, Figure 5.7) or an edge whose other triangle has
//    another active node, whose incision then ends there too. A node that separates two active
//    nodes and is closer than ε_edge to one of them is where both end. Where incisions ended,
//    nothing new is entered near them until the scalpel has moved 2 ε_exit away (2D's
//    forbidden edges, Figure 5.7);
//  * new incisions begin in one of the three ways of Figure 5.12, on triangles that touch no
//    active node: the swept scalpel crossing a boundary edge into its triangle, an end of the
//    scalpel passing through a triangle, or the swept scalpel meeting an interior edge from
//    outside both its triangles (a fold's crest), which branches at the next step. The
//    candidates come from a uniform grid (TriangleGrid). A scalpel placed through the surface
//    (the first move after construction or lift()) enters where it pierces it.
// Every triangle touches at most one active node (§5.3.2): flips that would join two, removals
// of nodes between two, and entries into triangles of an active node are refused.
// Edits that others make to the mesh between moves keep the incisions right, as for the 2D
// cutter (IncisionWatch): an incision whose tip they took away ends, and the next move raises
// IncisionLost naming it.
// Departures from the thesis: the incision split's new nodes go on the cut edges (a chord of
// the path), not onto the path itself, which they approach where the surface is flatter than a
// crease; a node separating two incisions annihilates them only when
// it is within ε_edge, and the edge case inserts the node where the scalpel crosses the edge
// rather than on the extrapolated path.
#pragma once

#include <optional>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cutting/cut_body.hpp"
#include "cutting/cut_thresholds.hpp"
#include "cutting/delaunay_cutter.hpp"
#include "cutting/incision_star.hpp"
#include "cutting/sweep_triangle.hpp"
#include "cutting/triangle_grid.hpp"

namespace snede {

// The distances (0 means the thesis's default); the surface cutter has no other option.
using SurfaceCutterOptions = CutThresholds;

class SurfaceCutter {
 public:
  // Cuts `mesh` (triangles in 3D). With the displacement of a body on this mesh the scalpel
  // moves in deformed coordinates X + u; without (an unset source), in the mesh's own. Throws
  // std::invalid_argument for another kind of mesh, or negative or non-finite thresholds.
  SurfaceCutter(Mesh& mesh, DisplacementSource displacement, SurfaceCutterOptions options);

  // Moves the scalpel to `segment` (6 numbers: its two ends, deformed coordinates); the first
  // move after construction or lift() places it, entering where it pierces the surface.
  // Throws std::invalid_argument, before changing anything, for non-finite coordinates or
  // coinciding ends, and IncisionLost when edits by others took an incision's tip away since
  // the last move (that incision has ended; the next move goes on with the others). The
  // report's fields mean what they mean for the 2D cutter.
  PlanarCutResult move(std::span<const double> segment);
  // Lifts the scalpel: the incisions in progress stay as they are and stop being active.
  void lift();

  // The active nodes of the incisions in progress (entry nodes included), oldest first.
  std::vector<VertexId> active_nodes() const;
  bool cutting() const { return !incisions_.empty(); }
  std::vector<VertexId> incision_edges() const;
  const SurfaceCutterOptions& options() const { return options_; }

 private:
  struct Segment {
    Point3 head, tail;
  };
  struct Incision {
    VertexId active;
    bool entering;   // the entry node: nothing cut yet
    bool branching;  // entered at a fold's crest: expected to branch
  };
  struct StarHit {  // the scalpel meets triangle (b, y, z) at these barycentric weights
    Wedge wedge;
    std::array<double, 3> weights;
  };
  struct LinkCrossing {  // the swept scalpel meets link edge (y, z) at y + mu (z − y)
    Wedge wedge;
    double time, mu;
  };
  struct Contact {  // where the scalpel first touches the surface away from every incision
    enum class Way { boundary_edge, tip, crest } way;
    double time;                    // fraction of the step
    ElementId element;
    Simplex triangle;               // the element's simplex when the contact was found
    std::array<double, 3> weights;  // in its oriented vertex order; 0 opposite the edge for edge ways
  };

  Point3 reference(VertexId v) const;
  Point3 deformed(VertexId v) const;
  // Records where a vertex just added or moved with these parents is in deformed space.
  void follow(VertexId v, const VertexParents& parents);
  std::vector<Wedge> wedges(VertexId b) const;
  bool on_boundary(VertexId v) const;
  bool is_active(VertexId v) const;
  Incision* incision_at(VertexId active);
  // The active nodes adjacent to v other than `except`.
  std::vector<VertexId> active_neighbours(VertexId v, VertexId except) const;
  bool touches_active(ElementId triangle, VertexId except = -1) const;
  // Whether every triangle of v's star, with v moved to x, turns its normal by less than 60°
  // and ends within 60° of the star's vector area, or no further from it than before (those
  // with vertex merging_into, which a collapse into it removes, aside). If not, the first
  // triangle refused goes to *refused_by.
  Point3 star_area(VertexId v) const;  // the vector area of v's star (twice)
  // The uncut surface's normal at v (not normalised): its star's vector area when the cutter
  // was made, interpolated to the vertices made since as their points are.
  Point3 surface_normal(VertexId v) const;
  // Whether a triangle with this normal and corners faces the way the uncut surface does there.
  bool faces_surface(const Point3& normal, VertexId a, VertexId b, VertexId c) const;
  bool keeps_facing(VertexId v, const Point3& x, VertexId merging_into = -1, Wedge* refused_by = nullptr) const;
  // Whether interior edge (p, q) bends by 45° or more (its two triangles' normals).
  bool bends(VertexId p, VertexId q) const;
  // Whether edge (p, q) is on a crease: it bends, and both ends are crease vertices (so that
  // triangles the cutter squeezed on a smooth surface make no crease); and whether one of v's
  // spokes is: v sits on a crease.
  bool is_crease(VertexId p, VertexId q) const;
  bool on_crease(VertexId v) const;
  // The shortest cut edge a crease makes: a node on a crease waits until the scalpel is this
  // far from it.
  double crease_step() const { return options_.eps_edge / 4; }
  bool is_boundary_edge(ElementId triangle, VertexId opposite) const;
  Point3 reference_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights) const;
  Point3 deformed_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights) const;

  std::vector<StarHit> hits_in_star(VertexId b, const Segment& scalpel) const;  // nearest b first
  std::optional<LinkCrossing> first_link_crossing(VertexId b, const Segment& from, const Segment& to) const;
  // The scalpel moved across, parallel to itself, so that its line passes through x.
  static Segment through(const Segment& scalpel, const Point3& x);
  double step_limit(VertexId b, const Segment& scalpel) const;  // d_max, Figure 5.11
  std::vector<ElementId> triangles_near(const Segment& from, const Segment& to);
  // Whether the scalpel meets a triangle with a vertex in a's star.
  bool meets_ring(VertexId a, const Segment& scalpel) const;
  // The candidate within `radius` of `at` nearest it that is neither active nor next to an
  // active node, or -1.
  VertexId free_vertex_near(const Point3& at, std::span<const VertexId> candidates, double radius) const;

  void sweep(const Segment& from, const Segment& to, PlanarCutResult& report);
  // How many distinct places the scalpel meets a's star at.
  std::size_t places_in_star(VertexId a, const Segment& scalpel) const;
  // Whether an entry node's star meets the scalpel in fewer places at `to` than at `from`
  // (than two for a crest).
  bool loses_place(const Segment& from, const Segment& to) const;
  void follow_scalpel(const Segment& from, const Segment& to, PlanarCutResult& report);
  // The earliest new contacts (simultaneous ones together) as the scalpel moves from `from`
  // to `to`, on triangles that touch no active node (surface_contacts.cpp).
  std::vector<Contact> first_contacts(const Segment& from, const Segment& to);
  // Where the scalpel pierces triangles that touch no active node, nearest its first end first.
  std::vector<Contact> piercings(const Segment& scalpel);
  // Whether the scalpel meets the triangle with a weight above a tolerance at `corner` (each
  // corner when corner is -1): not just on the opposite side.
  bool meets_inside(const Segment& scalpel, ElementId triangle, int corner) const;
  bool enter(const Contact& contact, PlanarCutResult& report);
  void begin_incision(VertexId a, const Segment& scalpel, PlanarCutResult& report);
  // Dissects the edges from a to `ends` (after splitting a lone interior one, so that it
  // opens); `ends` become the active nodes in place of a.
  void open_from(VertexId a, const std::vector<VertexId>& ends, PlanarCutResult& report);
  void advance(VertexId b, Segment from, const Segment& to, PlanarCutResult& report);
  // §5.3.1's incision nodes on the scalpel's path where it crosses a crease: b's incision
  // goes on from a node where the swept scalpel crosses link edge (y, z) of b's star (a new
  // one, or y or z when within crease_step of the crossing). Returns the new active node, or -1.
  VertexId cut_to_edge(VertexId b, VertexId y, VertexId z, double mu, PlanarCutResult& report);
  // b's incision goes on from a new node where the scalpel meets b's star (b on a crease
  // stays there). Returns the new active node, or -1.
  VertexId cut_to_hit(VertexId b, const StarHit& hit, PlanarCutResult& report);
  // Hits of `scalpel` in a's star farther than `apart` from a and from each other, or nothing
  // when fewer than two (Figure 5.14).
  std::vector<StarHit> branches(VertexId a, const Segment& scalpel, double apart) const;
  double branch_distance(VertexId a);  // `apart` for a's incision
  void branch(VertexId a, const Segment& scalpel, double apart, PlanarCutResult& report);
  // Moves the active node b to the point with `weights` in its star triangle, or part of the way;
  // true only for the whole way. When keeps_facing refuses the whole way, the star triangle in
  // the way goes to *blocking.
  bool move_active_to(VertexId b, const Wedge& w, std::array<double, 3> weights,
                      std::optional<Wedge>* blocking = nullptr);
  // A new vertex at `weights` in triangle (b, y, z), on a side when a weight is (nearly) 0.
  VertexId insert_at(const Wedge& w, VertexId b, const std::array<double, 3>& weights, PlanarCutResult& report);
  VertexId split(VertexId a, VertexId b, double t);
  bool flip(VertexId p, VertexId q, PlanarCutResult& report);
  // Link edge (y, z) of b's star out of the way: flipped, or else its nearer interior end removed.
  bool clear_link_edge(VertexId b, VertexId y, VertexId z, PlanarCutResult& report);
  bool remove_node(VertexId v, PlanarCutResult& report);
  void remesh_around(VertexId b, PlanarCutResult& report);
  void split_incision(VertexId b, PlanarCutResult& report);
  // Ends b's incision at edge (y, z) of its star (Figure 5.7, 5.13), with every incision
  // whose active node is across it.
  void end_at_edge(VertexId b, VertexId y, VertexId z, double mu, PlanarCutResult& report);
  // Ends b's incision at its neighbour w, with those of w's other active neighbours.
  void end_at_node(VertexId b, VertexId w, PlanarCutResult& report);
  // Ends the incisions of `actives` by dissecting their edges to w; returns the copies made.
  std::vector<VertexId> join_at(VertexId w, const std::vector<VertexId>& actives);
  std::vector<VertexId> dissect_edges(const std::vector<std::array<VertexId, 2>>& edges);
  void legalize(PlanarCutResult& report);
  // After edits by others: each active node is the heir that still carries its incision, or
  // the incision ends.
  void settle(const Connectivity& c, const IncisionWatch::Fates& fates);
  // The uncut surface's normal at a vertex another edit added or moved, as follow() does.
  void carry_normal(const VertexEvent& event);
  // Whether a vertex made with these parents is a crease vertex.
  void carry_crease(VertexId v, const VertexParents& parents);
  // What the cutter keeps about a vertex that is gone.
  void forget(VertexId v);

  Mesh& mesh_;
  DisplacementSource body_displacement_;
  SurfaceCutterOptions options_;
  std::vector<Incision> incisions_;
  std::optional<Segment> scalpel_;
  std::vector<double> displacement_;                // u at the start of the move (3 per point)
  std::unordered_map<VertexId, Point3> moved_;      // deformed positions of vertices edited since
  TriangleGrid grid_;
  std::optional<std::uint64_t> grid_revision_;  // the mesh's when the grid was built
  bool rebuild_grid_ = true;
  std::unordered_set<VertexId> incision_vertices_;
  std::unordered_map<VertexId, Point3> surface_normals_;
  // The vertices where the uncut surface bends at a spoke (by 45° or more), and those made on
  // edges between two of them or as their copies since.
  std::unordered_set<VertexId> crease_vertices_;
  std::vector<VertexId> touched_;
  std::unordered_set<ElementId> refused_;  // this move enters none of these (refused, or where an incision ended)
  // Where incisions ended: no entry into their stars until the scalpel is 2 ε_exit away (§5.2.2).
  std::unordered_set<VertexId> ended_;
  IncisionWatch watch_;                    // last: it refers to the sets above
};

}  // namespace snede
