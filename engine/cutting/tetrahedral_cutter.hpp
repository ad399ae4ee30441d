// Cutting a tetrahedral body with a scalpel (§3.2–§3.3), in the deformed configuration of a
// running simulation.
//
// The scalpel is a line segment; moving it sweeps a quadrilateral, processed as two sweep
// triangles. Each sweep triangle is one cut step:
//  1. face selection (§3.2.1, face_selection.hpp),
//  2. node snapping of the selected faces' vertices onto the sweep (§3.2.2, node_snapping.hpp),
//  3. dissection along the selected faces (§7.3, dissect.hpp),
//  4. degeneracy removal around the cut (§3.2.3, degeneracy_removal.hpp),
//  5. the pieces (§3.3, piece_tracker.hpp, a search local to the cut): a piece that the cut
//     separates from every constraint is reported and, by option, fixed on one face so that
//     the next static solve is well posed.
// Steps 3–5 are one change for the mesh's watchers, so a body (its displacement, velocity and
// constraints carried to new and moved vertices by their parents) reissues its sizes once per
// sweep triangle, and the solvers continue on the new mesh from the carried state.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cutting/cut_body.hpp"
#include "cutting/cut_result.hpp"
#include "cutting/face_selection.hpp"
#include "mesh/deformed_positions.hpp"
#include "mesh/piece_tracker.hpp"
#include "topology/degeneracy_removal.hpp"

namespace snede {

struct CutterOptions {
  bool snap = true;
  bool remove_degeneracies = true;
  DegeneracyOptions degeneracy;
  bool fix_free_pieces = true;
  // A piece a sweep separates whose volume is at most this many mean elements of the mesh is
  // removed (0: kept). The cut surface is placed only to within about one element (snapping
  // moves a vertex by up to half an edge), so a piece about two elements across or less is an
  // artefact of that approximation (flat tetrahedra between two cut faces), not a part of the
  // body the scalpel meant to separate.
  int max_fragment_elements = 10;
};

// What a cutter remembers between sweeps, by vertices of its mesh, so that it can go on in a
// copy of the mesh numbered otherwise (a distributed body's cutting rank, issue 52): faces and
// tetrahedra as oriented simplices, found again by their vertices.
struct CutterMemory {
  std::optional<std::array<double, 6>> scalpel;  // where the scalpel is, if placed
  std::vector<double> cut_configuration;         // 3 per mesh row while an incision is open, else empty
  std::vector<VertexId> placed;                  // vertices snapped or on the incision
  std::vector<Simplex> joined;                   // selected faces the dissection left joined
  std::vector<Simplex> incision;                 // the incision's boundary faces
  std::vector<std::array<double, 9>> sweeps;     // the remembered sweep triangles, oldest first
  std::vector<Simplex> previous_touched;         // the tetrahedra the latest sweep met
};

class TetrahedralCutter : public ConnectivityWatcher {
 public:
  // Cuts `mesh` (tetrahedral). With a simulated body on this mesh the scalpel acts on the
  // deformed body X + u, supports are not snapped and free pieces are held by `body`; with an
  // empty one, on the mesh as it is. Throws std::invalid_argument for a mesh that is not
  // tetrahedral or bad thresholds.
  TetrahedralCutter(Mesh& mesh, CutBody body, CutterOptions options);
  ~TetrahedralCutter() override;
  TetrahedralCutter(const TetrahedralCutter&) = delete;
  TetrahedralCutter& operator=(const TetrahedralCutter&) = delete;

  // One sweep triangle, corners (3, 3) in deformed coordinates. Throws std::invalid_argument,
  // before changing anything, for non-finite or collinear corners. A triangle that misses the
  // body gives an empty report.
  CutResult cut_triangle(std::span<const double> corners);
  // Moves the scalpel, a segment (2, 3), from its previous position: the two sweep triangles
  // between them. The first call only places the scalpel. Throws std::invalid_argument for a
  // non-finite or zero-length segment; a move that sweeps no area gives an empty report.
  CutResult move(std::span<const double> scalpel);
  bool placed() const { return scalpel_.has_value(); }
  // Lifts the scalpel out of the body: the next move only places it, and the next sweep
  // starts a new incision (earlier sweeps no longer count for the tetrahedra they left
  // incomplete, and faces left joined are not cut again).
  void lift();

  // The incision: the boundary faces the cuts opened, (n, 3) vertex ids oriented outward. It
  // follows later edits (§7.4): a face whose vertices a collapse substituted, and the faces a
  // split or bisection of an incision face made inside it.
  std::vector<VertexId> incision_faces() const;
  const CutterOptions& options() const { return options_; }

  // The memory above, in this mesh's vertex ids.
  CutterMemory memory() const;
  // Goes on from `memory` (in this mesh's vertex ids; a new cutter, before its first cut).
  // Throws std::invalid_argument, before changing anything, for a face or tetrahedron the mesh
  // does not have, a vertex out of range, or a cut configuration of another size.
  void restore(const CutterMemory& memory);

  void init(const Connectivity&) override {}
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;

 private:
  // One sweep triangle against cut_positions(): what cut_triangle and move do.
  CutResult cut(const SweepTriangle& sweep);
  // Snaps the selected faces' vertices; returns those moved.
  std::vector<VertexId> snap(const FaceSelection& selection, CutResult& report);
  std::vector<VertexId> dissect_selected(std::vector<FaceId> faces, CutResult& report);
  void count_pieces(CutResult& report);
  // Removes the pieces of at most max_fragment_elements mean elements' volume (never the
  // largest piece); true if any.
  bool remove_fragments(CutResult& report);
  bool constrained(VertexId v) const;
  // The body's owner for one cut, when the cutter has a body (cut_body.hpp).
  std::optional<ExclusiveUse::Claim> claim_body() const;
  // A copy of the body's displacement as it is now.
  std::vector<double> displacement_now() const;
  // Where the scalpel meets the body: X + u with u the displacement the incision was begun in
  // (see cut_configuration_), or X for a bare mesh.
  DeformedPositions cut_positions() const;

  Mesh& mesh_;
  CutBody body_;
  CutterOptions options_;
  FaceSelector selector_;
  std::unordered_set<VertexId> placed_;          // vertices already snapped or on the incision
  std::vector<std::pair<FaceId, Simplex>> joined_;  // selected faces the dissection left joined
  std::unordered_map<FaceId, Simplex> incision_;
  std::optional<std::array<double, 6>> scalpel_;
  // The displacement of the body when the scalpel was placed (3 per mesh row, carried to new
  // and moved vertices like the body's own): every sweep of one incision is made against it.
  // Against the displacement of each move instead, a body relaxed between moves (the lips
  // opening under gravity, Figure 3.17) has moved its incision's front away from where the
  // next sweep starts, and a sweep across the whole body left a bridge of material.
  std::vector<double> cut_configuration_;
  PieceTracker pieces_;
};

}  // namespace snede
