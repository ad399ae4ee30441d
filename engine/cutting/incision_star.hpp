// What the Delaunay cutters (§5.2 in the plane, §5.3 on surfaces) ask of the triangles around
// an incision's active node, the same in both: its star as wedges, boundary tests, the flips
// towards Delaunay, the lips' edges, and how they follow edits that others make to the mesh.
#pragma once

#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cutting/planar_cut_result.hpp"
#include "mesh/mesh.hpp"
#include "topology/flip_edge.hpp"

namespace snede {

struct Wedge {  // triangle (b, y, z) of b's star, in its orientation
  ElementId element;
  VertexId y, z;
};

std::vector<Wedge> star_wedges(const Connectivity& c, VertexId b);

// Whether the edge of `triangle` opposite its vertex `opposite` is on the boundary.
bool is_boundary_edge(const Connectivity& c, ElementId triangle, VertexId opposite);

// Whether v is on the boundary: an edge of its star from it or opposite it is.
bool touches_boundary(const Connectivity& c, VertexId v);

// The edges of the active triangles (link edges and spokes from b) flipped while one fails
// the (unfolded) empty-circle test and `flip(p, q)` performs its flip (§5.2.2, §5.3.1).
template <class Flip>
void flip_star_towards_delaunay(const Mesh& mesh, VertexId b, const Flip& flip) {
  for (int round = 0; round < 64; ++round) {
    bool flipped = false;
    for (const Wedge& w : star_wedges(mesh.connectivity(), b)) {
      for (const auto& [p, q] : {std::pair{w.y, w.z}, std::pair{b, w.y}})
        if (!is_locally_delaunay(mesh, w.element, p, q) && flip(p, q)) {
          flipped = true;
          break;
        }
      if (flipped) break;
    }
    if (!flipped) break;
  }
}

// The boundary edges with both ends among `incision_vertices` (both lips), flattened pairs.
std::vector<VertexId> lip_edges(const Connectivity& c, const std::unordered_set<VertexId>& incision_vertices);

// The other ends of v's boundary edges (none for an unused vertex).
std::vector<VertexId> boundary_neighbours(const Connectivity& c, VertexId v);

// Whether v can be an incision's tip: a vertex with exactly two boundary edges, both to
// incision vertices (the cut edges, §5.2.2). After an edit removed, merged or split the active
// node (`taking_over`), the vertex that carries the tip on must also have its cut edges almost
// coincide — less than 90° apart — so that a lip's corner a dissection left is not taken for it.
bool is_incision_tip(const Mesh& mesh, VertexId v, const std::unordered_set<VertexId>& incision_vertices,
                     bool taking_over);

// Raised by a cutter's move when edits others made since its last move took an incision's
// active node away and left no vertex that is that incision's tip; the message names the
// node and what happened to it. Python sees snede.planar_cutting.IncisionLost, a RuntimeError.
class IncisionLost : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A cutter's incisions as edits made by others between its moves leave them (§7.4: the cutter
// watches the mesh). Ids are not names: a vertex another edit removes is gone from the
// incision even when a later edit reuses its id for a vertex elsewhere. The watch hears every
// operation, to record what became of the vertices the cutter holds, and the end of every
// change, when the mesh is valid again, to settle them:
//  * a removed vertex leaves the incision vertices and the sets given to forget_removed_from;
//  * boundary edges the edits made that lead from an incision vertex along the boundary to
//    another one take the place of the lip they replaced: the vertices between join the
//    incision (a lip edge split or bisected, a lip vertex merged into its neighbour, triangles
//    along a lip removed);
//  * an active node's heirs — itself if it is still there, the vertex a collapse merged it
//    into (the one that took its place in its elements), its dissection copies — go to the
//    cutter's `settled`, which keeps the one that is still the incision's tip or gives the
//    incision up.
// The cutter's own edits are not recorded (OwnEdits): it keeps its books as it makes them.
class IncisionWatch {
 public:
  struct Fate {
    std::vector<VertexId> heirs;  // live vertices that may carry the tip on, the node itself first
    std::string change;           // what happened to the node, for an error message
  };
  using Fates = std::unordered_map<VertexId, Fate>;  // by active node, only those edits touched
  // Told when edits by others are over (the mesh valid again): the fates of the followed
  // active nodes that changed. The cutter must follow() its active nodes again, and may not
  // edit the mesh from here.
  using Settled = std::function<void(const Connectivity&, const Fates&)>;
  // Each vertex event of an edit by others, in order, as it is heard.
  using VertexEventHook = std::function<void(const VertexEvent&)>;

  IncisionWatch(Connectivity& connectivity, std::unordered_set<VertexId>& incision_vertices, Settled settled,
                VertexEventHook on_vertex_event = {});
  ~IncisionWatch();
  IncisionWatch(const IncisionWatch&) = delete;
  IncisionWatch& operator=(const IncisionWatch&) = delete;

  // Follows these active nodes from now on.
  void follow(std::span<const VertexId> actives);
  // `set` loses the vertices that edits by others remove (it is the cutter's, and outlives the watch).
  void forget_removed_from(std::unordered_set<VertexId>& set) { plain_sets_.push_back(&set); }
  // Settles what edits by others did, if anything, now: at the start of a move, which a batch
  // of edits may still be open around.
  void settle();
  // Called by `settled` for an incision given up: the next settle_before_move raises IncisionLost(why).
  void lose(std::string why);
  // At the start of a move, before it changes anything: settles, and raises IncisionLost if
  // an incision was given up since the last move.
  void settle_before_move();

  // While one is alive, operations are the cutter's own.
  class OwnEdits {
   public:
    explicit OwnEdits(IncisionWatch& watch) : watch_(watch) { ++watch_.own_; }
    ~OwnEdits() { --watch_.own_; }
    OwnEdits(const OwnEdits&) = delete;
    OwnEdits& operator=(const OwnEdits&) = delete;

   private:
    IncisionWatch& watch_;
  };

 private:
  // Hears each operation (WatchMode::each_operation), and the end of each change (merged).
  struct Recorder : ConnectivityWatcher {
    explicit Recorder(IncisionWatch& w) : watch(w) {}
    void init(const Connectivity&) override {}
    void on_change(const Connectivity& c, const ConnectivityChange& change) override { watch.record(c, change); }
    IncisionWatch& watch;
  };
  struct Settler : ConnectivityWatcher {
    explicit Settler(IncisionWatch& w) : watch(w) {}
    void init(const Connectivity&) override {}
    void on_change(const Connectivity&, const ConnectivityChange&) override { watch.settle(); }
    IncisionWatch& watch;
  };

  void record(const Connectivity& c, const ConnectivityChange& change);
  void forget(VertexId v);
  // The vertices between incision vertices along boundary edges the edits made.
  void join_new_lips(const Connectivity& c);
  // u carries on (part of) x: an heir of x's active node, if x is followed.
  void inherit(VertexId x, VertexId u, const std::string& how);
  Fate& fate_of(VertexId active);

  Connectivity& connectivity_;
  std::unordered_set<VertexId>& incision_;
  Settled settled_;
  VertexEventHook on_vertex_event_;
  std::vector<std::unordered_set<VertexId>*> plain_sets_;
  int own_ = 0;
  bool changed_ = false;               // edits by others since the last settle
  std::vector<FaceId> entered_;         // boundary faces those edits made
  std::unordered_map<VertexId, VertexId> heir_of_;  // followed vertex → the active node it may carry on
  Fates fates_;
  std::string lost_;                    // why incisions were given up, for the next move
  Recorder recorder_{*this};
  Settler settler_{*this};
};

// One move of a Delaunay cutter, from its start — edits by others settled (settle_before_move,
// which may raise IncisionLost), the cutter's own edits from then on (OwnEdits), the clock and
// the triangle count taken — to finished(), which completes and returns its report.
class CutterMove {
 public:
  CutterMove(IncisionWatch& watch, const Mesh& mesh);
  PlanarCutResult& report() { return report_; }
  PlanarCutResult finished();

 private:
  static IncisionWatch& settled(IncisionWatch& watch);

  const Mesh& mesh_;
  IncisionWatch::OwnEdits own_;
  double start_;
  PlanarCutResult report_;
};

}  // namespace snede
