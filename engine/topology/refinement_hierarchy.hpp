// The bisection hierarchy (§6.5): every element ever split is a node whose two children are
// its halves, so the tree is a BSP tree (each split is a hyperplane through the midpoint of
// the refinement edge) usable for point location and, later, for multilevel solvers.
//
// It also keeps the bisection labelling (TaggedSimplex) of every live element, keyed by
// element id, and the labelling rule (initial_labelling.hpp), chosen from the starting mesh. As a connectivity watcher (§7.4) it follows every change: splits announced by
// expect_split become children; elements removed by another operation leave their node as a
// dead leaf; elements added by another operation start new roots, labelled afresh; elements
// changed by a vertex substitution (a cut) start new roots keeping their labelling with the
// substituted vertices.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "mesh/mesh.hpp"
#include "topology/initial_labelling.hpp"
#include "topology/root_grid.hpp"
#include "topology/tagged_simplex.hpp"

namespace snede {

struct RefinementNode {
  TaggedSimplex label;
  NodeId parent = no_id;
  std::array<NodeId, 2> children{no_id, no_id};  // children[0] keeps x0, children[1] keeps xk (of label)
  ElementId element = no_id;  // the live element of a leaf; no_id once split or removed
  bool is_leaf() const { return children[0] == no_id; }
};

class RefinementHierarchy : public ConnectivityWatcher {
 public:
  // Labels every element of `mesh` as a root (initial_labelling) and starts watching it. The
  // 3D rule is chosen from the mesh unless given (a rank's part of a distributed mesh takes the
  // rule every rank agreed on, which the whole mesh would choose); `root_labels`, one per
  // element id, replace initial_labelling (a part refined before goes on with the labels its
  // cells had, as a serial hierarchy would).
  explicit RefinementHierarchy(Mesh& mesh, std::optional<BisectionRule> rule = std::nullopt,
                               std::vector<TaggedSimplex> root_labels = {});
  ~RefinementHierarchy() override;
  RefinementHierarchy(const RefinementHierarchy&) = delete;
  RefinementHierarchy& operator=(const RefinementHierarchy&) = delete;

  std::size_t n_nodes() const { return nodes_.size(); }
  // Bisections recorded (each adds two children; other edits add roots): only a refinement
  // changes it.
  std::size_t n_splits() const { return (nodes_.size() - roots_.size()) / 2; }
  const RefinementNode& node(NodeId n) const { return nodes_[n]; }
  const std::vector<NodeId>& roots() const { return roots_; }
  NodeId node_of(ElementId e) const;
  const TaggedSimplex& label(ElementId e) const { return nodes_[node_of(e)].label; }
  // Number of bisections between the element's root and it.
  int level(ElementId e) const;
  // The vertex that bisected a split node's refinement edge (the one corner of its halves it
  // lacks; the halves' labels may order their corners by another rule than Maubach's).
  VertexId midpoint(NodeId split) const;
  // The labelling rule of this mesh's 3D bisection, chosen when the hierarchy starts.
  BisectionRule rule() const { return rule_; }

  // The next replace_elements removes `parent` and adds `children` (in this order among its
  // new simplexes); called once per split element before that replace_elements.
  void expect_split(ElementId parent, const std::array<TaggedSimplex, 2>& children);

  // Point location through the tree: the live elements whose closure contains x (a point on
  // a shared face or edge lies in several), found by descending from the roots that contain
  // it into the half on x's side of each bisecting hyperplane. x: (dim,).
  std::vector<ElementId> locate_all(std::span<const double> x) const;
  // The same in two steps, for repeated queries at one point while the mesh is refined:
  // the roots containing x (those near x, found through a grid over the roots' boxes, built
  // on first use and after a change that moved a vertex), then the descent from them.
  std::vector<NodeId> roots_containing(std::span<const double> x) const;
  // The roots whose boxes meet `box`, in the order of roots() (a surface's: every root), so
  // that a search near a segment descends from those alone (refine_near_segment).
  std::vector<NodeId> roots_meeting(const BoundingBox& box) const;
  std::vector<ElementId> locate_all(std::span<const double> x, std::span<const NodeId> roots) const;
  // One live element containing x, or no_id if x is outside the mesh.
  ElementId locate(std::span<const double> x) const;

  std::size_t memory_bytes() const;

  void init(const Connectivity& connectivity) override;
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;

 private:
  NodeId add_node(const TaggedSimplex& label, NodeId parent, ElementId element);
  void add_root(const TaggedSimplex& label, ElementId element);
  // The box of the root's simplex at the current coordinates, padded by more than the
  // barycentric tolerance of point location.
  BoundingBox padded_box(NodeId root) const;
  void attach(ElementId e, NodeId n);
  // x's barycentric coordinates in the node's simplex, in label order (x0..xd).
  std::array<double, max_dimension + 1> barycentric(const TaggedSimplex& label, std::span<const double> x) const;
  TaggedSimplex relabelled(const TaggedSimplex& old_label, const Simplex& old_simplex, const Simplex& new_simplex) const;

  struct ExpectedSplit {
    NodeId parent;
    std::array<TaggedSimplex, 2> children;
  };

  Mesh& mesh_;
  std::vector<RefinementNode> nodes_;
  std::vector<NodeId> roots_;
  std::vector<NodeId> node_of_element_;  // indexed by element id
  std::vector<ExpectedSplit> expected_;
  mutable RootGrid root_grid_;
  VertexId n_points_seen_ = 0;
  std::optional<BisectionRule> given_rule_;
  std::vector<TaggedSimplex> given_labels_;  // until init() takes them
  BisectionRule rule_ = BisectionRule::newest_vertex;  // ids below this may be in roots' labels: reusing one moves a root
};

}  // namespace snede
