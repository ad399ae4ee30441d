// Conforming bisection refinement (§6.5) in 2D and 3D: Maubach's bisection of tagged
// simplexes ([62]), which in 2D on right triangles is the thesis's hypotenuse (longest-edge,
// newest-vertex) bisection and in 3D on the Kuhn box keeps every element in one of 3
// similarity classes; other 3D meshes get longest-edge bisection (initial_labelling.hpp),
// whose closure stays near the refined region. Every change goes through
// Connectivity::replace_elements; new midpoints are added with Mesh::add_vertex first, so
// watchers (the model) carry the state over to them (§7.4).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "mesh/mesh.hpp"
#include "topology/refinement_hierarchy.hpp"

namespace snede {

// Every live element around an edge, where a walk across faces from one of them may not reach
// them all: on a rank's part of a distributed mesh, other ranks' cells can lie between the
// fans of cells around an edge of the rank boundary (rank_refinement.hpp).
class EdgeRings {
 public:
  virtual ~EdgeRings() = default;
  // The live elements containing edge (a, b), or empty to let the walk find them.
  virtual std::vector<ElementId> around(VertexId a, VertexId b) const = 0;
};

class Bisection {
 public:
  // Labels the mesh (initial_labelling; the 3D rule chosen from the mesh unless given; the
  // roots' labels given, one per element id, or found) and watches it for as long as this
  // object lives.
  explicit Bisection(Mesh& mesh, std::optional<BisectionRule> rule = std::nullopt,
                     std::vector<TaggedSimplex> root_labels = {});
  Bisection(const Bisection&) = delete;
  Bisection& operator=(const Bisection&) = delete;

  Mesh& mesh() { return mesh_; }
  const Mesh& mesh() const { return mesh_; }
  const RefinementHierarchy& hierarchy() const { return hierarchy_; }

  // §6.5 bisect(e) for the refinement edge of `element`: every element around that edge
  // whose refinement edge is another one is bisected first (recursively, with an explicit
  // stack), then all elements around the edge are split at its midpoint at once, so no
  // vertex is ever left hanging. Returns the number of elements split.
  // When the recursion would cycle — a labelling that is not compatible, as elements made by
  // other edits (flips, collapses, insertions) get — the requested edge is bisected at once:
  // every element around it is relabelled to have it as refinement edge. The mesh stays
  // conforming; only the bound on similarity classes is lost there (n_forced_splits counts).
  std::size_t bisect(ElementId element);

  // §6.5 uniform refinement, `levels` times: every element present at the start of a level
  // is bisected once (on the Kuhn box and on right-triangle grids, which are compatibly
  // labelled, this doubles the element count exactly). Returns the number of elements split.
  std::size_t refine_uniform(int levels);

  // Splits found around an edge by `rings` (which must outlive this object or be reset to
  // nullptr) as well as by the walk across faces.
  void set_edge_rings(const EdgeRings* rings) { rings_ = rings; }

  std::size_t memory_bytes() const { return hierarchy_.memory_bytes(); }
  // How many edges were bisected against an incompatible labelling (see bisect).
  std::size_t n_forced_splits() const { return n_forced_splits_; }

 private:
  struct EdgeToBisect {
    VertexId a, b;
    NodeId node;  // a hierarchy node whose simplex contains the edge
  };
  // A live element containing edge (a, b), found below `node` (the edge is in a child of
  // every split that did not bisect it).
  ElementId live_element_with_edge(NodeId node, VertexId a, VertexId b) const;
  // The simple-bisect of §6.5: `around` is every element containing (a, b); those whose
  // refinement edge is another are relabelled first (a forced split).
  std::size_t simple_bisect(VertexId a, VertexId b, const std::vector<ElementId>& around);
  // Every element containing (a, b), `start` among them.
  std::vector<ElementId> around_edge(VertexId a, VertexId b, ElementId start) const;

  Mesh& mesh_;
  RefinementHierarchy hierarchy_;
  std::size_t n_forced_splits_ = 0;
  const EdgeRings* rings_ = nullptr;
};

}  // namespace snede
