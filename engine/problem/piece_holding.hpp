// Whether constraints hold every piece of a mesh (§3.3: a cut can free a piece). A piece cut
// free of every support keeps its rigid motions, so the static problem has no unique solution,
// however many components the rest of the body has constrained: Newton spins to its iteration
// limit, CG meets an indefinite matrix. A piece is held when its constraints stop every rigid
// motion: the rows (I − P_v) R_v of its constrained vertices, R_v = [I | −[x_v]×] the
// infinitesimal rigid motions at x_v, have full rank (6 in 3D, 3 in 2D). A count of constrained
// components is not enough: two fixed vertices (6 components) leave the rotation about the line
// through them. A membrane, which tension holds (no bending stiffness: every support leaves it a
// linear mechanism), needs 6 constrained components, as before.
// A constrained vertex where pieces meet without a face (a hinge) counts for each of them; a
// free hinge for none, though it may help hold a piece: the check errs towards refusing, as a
// piece hinged there still turns about it unless held by constraints of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"
#include "problem/constraints.hpp"
#include "problem/rigid_motion_gram.hpp"

namespace snede {

// A piece of a mesh (cells joined through faces, §3.3) whose constraints do not stop all of
// its rigid motions.
struct LoosePiece {
  int piece = 0;   // label in [0, pieces)
  int pieces = 0;  // in the mesh
  std::size_t cells = 0;
  ElementId first_cell = no_id;  // its lowest cell id
  std::size_t constrained_components = 0;
  std::size_t rigid_motions_stopped = 0;  // rank of the constraints on the piece's rigid motions
  std::size_t rigid_motions = 0;          // 3 in 2D, 6 in 3D and on membranes
};

class PieceHolding {
 public:
  // For a question or two: the pieces are labelled from scratch (O(n)) once per topology
  // revision of the mesh.
  explicit PieceHolding(const Mesh& mesh);
  // For a solver asked before every solve (issue 49): follows the mesh's edits from the first
  // question on, so that after a cut the labels change only where the mesh did
  // (mesh/piece_tracker.hpp: a search local to the edit) and only the touched vertices' pieces
  // are found again. Every piece is labelled from scratch only when a piece split off or pieces
  // were joined, or when a piece is loose (so that its report does not depend on the history of
  // edits). `mesh` must outlive this.
  struct FollowEdits {};
  PieceHolding(Mesh& mesh, FollowEdits);
  ~PieceHolding();
  PieceHolding(const PieceHolding&) = delete;
  PieceHolding& operator=(const PieceHolding&) = delete;

  // The pieces `constraints` do not hold, by label. Each call accumulates each piece's
  // constraint rows (one pass over the vertices).
  std::vector<LoosePiece> loose_pieces(const Constraints& constraints);
  // Throws std::invalid_argument naming the first loose piece (its size, a vertex, the rigid
  // motions its constraints stop against those it has) and the remedies.
  void require_held(const Constraints& constraints);

  // How many times every piece was labelled from scratch (what following the edits saves).
  std::size_t whole_labellings() const { return whole_labellings_; }

 private:
  class EditWatcher;

  void label_from_scratch();
  void sort_hinges();
  template <class Label>
  void label_vertices(Label label, int pieces);
  void follow_edits();
  void label_vertex(VertexId v);
  std::vector<RigidMotionGram> grams(const Constraints& constraints) const;
  std::vector<LoosePiece> loose_of(const std::vector<RigidMotionGram>& grams, bool by_count) const;

  const Mesh& mesh_;
  Connectivity* followed_ = nullptr;      // null: labelled from scratch at each topology revision
  std::unique_ptr<EditWatcher> watcher_;  // attached at the first labelling of a followed mesh
  bool labelled_ = false;
  std::uint64_t labelled_revision_ = 0;   // the mesh's topology revision, when not followed
  std::uint64_t labelled_changes_ = 0;    // the watcher's changes heard, when followed
  bool labels_from_scratch_ = false;  // piece_cells_ and piece_first_cell_ are those of now
  int pieces_ = 0;
  std::vector<int> vertex_piece_;                       // per vertex id: a piece of its cells; -1 in none
  std::vector<std::pair<VertexId, int>> hinge_pieces_;  // a vertex in several pieces, with each further one
  std::vector<std::size_t> piece_cells_;
  std::vector<ElementId> piece_first_cell_;
  std::size_t whole_labellings_ = 0;
};

// The error a static solve gives when pieces are not held: the first of `loose` (naming
// `vertex_of_first`, a vertex of it) and the remedies.
std::string not_held_message(const std::vector<LoosePiece>& loose, std::int64_t vertex_of_first);

}  // namespace snede
