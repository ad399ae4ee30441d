// Delaunay cutting of a 2D triangle mesh with a point scalpel (§5.2.2), on a body that may be
// deformed: the scalpel moves in deformed coordinates and is followed in the reference
// configuration, where the mesh is edited.
//
// The scalpel is attached to the active node, a boundary vertex at the tip of the incision
// whose two boundary edges (the cut edges) are the incision's lips. Each move:
//  * moves the active node towards the scalpel as far as its triangles stay positive; the
//    edge ahead that would invert is flipped away (or, if the flip is not convex, its nearer
//    interior end removed), so large moves are taken in steps and never invert a triangle;
//  * flips the edges of the active triangles that are not locally Delaunay (exact in_circle);
//  * removes interior nodes closer to the active node than ε_edge — or, scale free, those
//    whose edge to it faces only angles below a threshold (§5.5);
//  * splits the incision where the cut edges, seen as one edge, fail the empty-circle test
//    (Figure 5.5): new nodes on both lips where the line through the opposite nodes crosses
//    the scalpel's path — unless one would fall within ε_edge/2 of an opposite node, which is
//    then removed if it is interior (it would leave a sliver).
// Entry (Figure 5.6): the scalpel's path crossing the boundary makes (or, within ε_entry of a
// vertex, picks) the entry node; the incision is postponed until the scalpel is ε_entry inside,
// then a node is inserted at the scalpel, joined to the entry node by flips, and that edge is
// dissected. Exit (Figure 5.7): when the active node's way crosses the boundary, or the move
// extrapolated by ε_exit would, a node is made there (or picked within ε_exit), the edge to it
// is dissected and the short edges it leaves are contracted; entries within ε_exit of an exit
// are ignored until the scalpel has moved 2 ε_exit away from it (the forbidden edges).
//
// Edits that others make to the mesh between moves (§7.4: the cutter watches the mesh) keep
// the incision right: its vertices follow splits, bisections, collapses and removals, and the
// active node follows a collapse into its neighbour or a dissection to the vertex that is then
// the incision's tip; when no vertex is, the next move raises IncisionLost (incision_star.hpp).
// Departures from the thesis: the dent of a postponed entry is not drawn (the entry node stays
// on the boundary until the fix-up); a new incision node goes on the path (the active node's
// trail) where the line through the opposite nodes crosses it, and on the cut edges' chord
// only where that line misses the trail; the two lips' nodes coincide instead of being
// dilated.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <unordered_set>
#include <vector>

#include "cutting/cut_body.hpp"
#include "cutting/cut_thresholds.hpp"
#include "cutting/incision_star.hpp"
#include "cutting/planar_cut_result.hpp"

namespace snede {

// The distances (CutThresholds: 0 means the thesis's default) and the short-edge angle.
struct DelaunayCutterOptions : CutThresholds {
  // > 0 (radians): an interior neighbour of the active node is removed when every angle
  // facing their edge is below this, instead of the distance ε_edge (scale free, §5.5).
  double short_edge_angle = 0;

  // Every setting with its name: the one list that bindings read (snede.DelaunayCutterOptions).
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    CutThresholds::visit_fields(visit);
    visit("short_edge_angle", &DelaunayCutterOptions::short_edge_angle);
  }
};

class DelaunayCutter {
 public:
  // Cuts `mesh` (triangles in 2D). With the displacement of a body on this mesh the scalpel
  // moves in deformed coordinates X + u; without (an unset source), in the mesh's own. Throws
  // std::invalid_argument for another kind of mesh, negative or non-finite thresholds.
  DelaunayCutter(Mesh& mesh, DisplacementSource displacement, DelaunayCutterOptions options);

  // Moves the scalpel to `point` (2 numbers, deformed coordinates). Throws
  // std::invalid_argument, before changing anything, for a non-finite point, and IncisionLost
  // when edits by others took the incision's tip away since the last move (the scalpel is
  // lifted then: the next move only places it).
  PlanarCutResult move(std::span<const double> point);
  // Lifts the scalpel: an incision in progress stays as it is, the next move only places it.
  void lift();

  // The active node, or -1 when no incision is in progress.
  VertexId active_node() const { return phase_ == Phase::cutting ? active_ : -1; }
  bool cutting() const { return phase_ == Phase::cutting; }
  // Boundary edges made by the cuts (both lips), (n, 2) vertex ids.
  std::vector<VertexId> incision_edges() const;
  // The thresholds in use (defaults resolved from the mesh at construction).
  const DelaunayCutterOptions& options() const { return options_; }

 private:
  enum class Phase { outside, entering, cutting };
  using Point = std::array<double, 2>;
  struct Crossing {  // where a segment meets boundary edge (y, z): y + lambda (z − y)
    VertexId y, z;
    double lambda, s;  // s: fraction along the segment
  };

  Point reference(VertexId v) const;
  // u: the body's displacement (2 per point), empty for a bare mesh (then deformed = reference).
  Point deformed(VertexId v, std::span<const double> u) const;
  // The triangle holding x in deformed coordinates, walked to from vertex `from` (O(walk));
  // the mesh is scanned only when the walk leaves the body. no_id if x is outside.
  ElementId locate(const Point& x, std::span<const double> u, VertexId from) const;
  // The reference position of the material point at deformed x, or nothing outside the body.
  std::optional<Point> to_reference(const Point& x, std::span<const double> u, VertexId from) const;
  // Where the active node should go for a scalpel at x (deformed): its reference position, or
  // outside the body its image under the affine map of the active triangle facing it.
  Point target_of(const Point& x, std::span<const double> u) const;
  std::vector<Wedge> wedges(VertexId b) const;
  bool on_boundary(VertexId v) const;
  std::optional<Crossing> first_boundary_crossing(const Point& from, const Point& to, std::span<const double> u) const;

  void enter(const Crossing& crossing, PlanarCutResult& report);
  bool fix_up_entry(const Point& p, PlanarCutResult& report);
  bool recover_edge(VertexId a, VertexId b, PlanarCutResult& report);
  // Moves the active node towards T (reference): true if it got there; an exit ends the cut.
  bool advance(const Point& target, PlanarCutResult& report);
  bool move_active_to(const Point& x);
  void remesh_around(VertexId b, PlanarCutResult& report);
  // Flips edge (p, q); the quadrilateral's corners count as touched.
  bool flip(VertexId p, VertexId q, PlanarCutResult& report);
  // Removes interior node v (retriangulating its star); its neighbours count as touched.
  bool remove_node(VertexId v, PlanarCutResult& report);
  // Lawson flips from the edges around the vertices this move touched until every interior
  // edge there is locally Delaunay (the rest of the mesh was not changed).
  void legalize(PlanarCutResult& report);
  void split_incision(PlanarCutResult& report);
  struct TrailCrossing {
    Point point;
    std::size_t segment;  // trail_[segment] → trail_[segment + 1]
  };
  // Where segment p→q crosses the trail, the crossing nearest to `near`.
  std::optional<TrailCrossing> trail_crossing(const Point& p, const Point& q, const Point& near) const;
  // Moves both copies of a new incision node to x; false (nothing moved) if either is refused.
  bool move_lips_to(const Point& x, std::array<VertexId, 2> copies, std::array<std::array<VertexId, 3>, 2> own_triangles);
  void predict_exit(const Point& direction, PlanarCutResult& report);
  void exit_through(VertexId y, VertexId z, double lambda, PlanarCutResult& report);
  std::vector<VertexId> dissect_edge(VertexId a, VertexId b);
  // After edits by others: the active node is the heir that is still the tip, or the
  // incision is given up.
  void settle(const Connectivity& c, const IncisionWatch::Fates& fates);

  Mesh& mesh_;
  DisplacementSource displacement_;
  DelaunayCutterOptions options_;
  Phase phase_ = Phase::outside;
  VertexId active_ = -1;
  Point entry_{};
  std::optional<Point> scalpel_;       // last scalpel position (deformed)
  std::optional<Point> last_target_;   // last reference position the active node was sent to
  std::optional<Point> exit_point_;    // the scalpel (deformed) at the last exit
  std::unordered_set<VertexId> forbidden_;  // boundary vertices of that exit: no entry near them
  std::unordered_set<VertexId> incision_vertices_;
  std::vector<VertexId> touched_;  // vertices whose stars this move changed
  // Reference positions of the active node since the newest incision node behind it (first).
  std::vector<Point> trail_;
  IncisionWatch watch_;  // last: it refers to the sets above
};

}  // namespace snede
