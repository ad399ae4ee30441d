#include "topology/refinement_hierarchy.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <stdexcept>
#include <utility>

#include "topology/initial_labelling.hpp"

namespace snede {
namespace {

// Barycentric coordinates are dimensionless: a point this close to a face counts as on it.
constexpr double on_face_tolerance = 1e-10;

}  // namespace

RefinementHierarchy::RefinementHierarchy(Mesh& mesh, std::optional<BisectionRule> rule,
                                         std::vector<TaggedSimplex> root_labels)
    : mesh_(mesh), given_rule_(rule), given_labels_(std::move(root_labels)) {
  mesh_.connectivity().add_watcher(this, WatchMode::each_operation);  // follows every split
}

RefinementHierarchy::~RefinementHierarchy() { mesh_.connectivity().remove_watcher(this); }

void RefinementHierarchy::init(const Connectivity& connectivity) {
  nodes_.clear();
  roots_.clear();
  root_grid_.clear();
  node_of_element_.assign(connectivity.element_capacity(), no_id);
  rule_ = given_rule_ ? *given_rule_ : bisection_rule_for(mesh_);
  for (ElementId e : connectivity.element_ids())
    add_root(given_labels_.empty() ? initial_labelling(mesh_, connectivity.element(e).simplex, rule_)
                                   : given_labels_.at(static_cast<std::size_t>(e)),
             e);
  std::vector<TaggedSimplex>().swap(given_labels_);
  n_points_seen_ = mesh_.n_points();
}

void RefinementHierarchy::add_root(const TaggedSimplex& label, ElementId element) {
  roots_.push_back(add_node(label, no_id, element));
  if (root_grid_.built()) root_grid_.add(roots_.back());
}

NodeId RefinementHierarchy::add_node(const TaggedSimplex& label, NodeId parent, ElementId element) {
  const auto n = static_cast<NodeId>(nodes_.size());
  RefinementNode node;
  node.label = label;
  node.parent = parent;
  nodes_.push_back(node);
  attach(element, n);
  return n;
}

void RefinementHierarchy::attach(ElementId e, NodeId n) {
  if (node_of_element_.size() <= static_cast<std::size_t>(e)) node_of_element_.resize(e + 1, no_id);
  node_of_element_[e] = n;
  nodes_[n].element = e;
}

NodeId RefinementHierarchy::node_of(ElementId e) const {
  if (e < 0 || static_cast<std::size_t>(e) >= node_of_element_.size() || node_of_element_[e] == no_id)
    throw std::invalid_argument("refinement hierarchy: element " + std::to_string(e) + " is not a live element");
  return node_of_element_[e];
}

VertexId RefinementHierarchy::midpoint(NodeId split) const {
  const RefinementNode& parent = nodes_[split];
  const TaggedSimplex& half = nodes_[parent.children[0]].label;
  for (int i = 0; i <= half.dim; ++i)
    if (!parent.label.contains(half.vertex[i])) return half.vertex[i];
  throw std::logic_error("refinement hierarchy: node " + std::to_string(split) + " has no midpoint");
}

int RefinementHierarchy::level(ElementId e) const {
  int depth = 0;
  for (NodeId n = nodes_[node_of(e)].parent; n != no_id; n = nodes_[n].parent) ++depth;
  return depth;
}

void RefinementHierarchy::expect_split(ElementId parent, const std::array<TaggedSimplex, 2>& children) {
  expected_.push_back({node_of(parent), children});
}

TaggedSimplex RefinementHierarchy::relabelled(const TaggedSimplex& old_label, const Simplex& old_simplex,
                                              const Simplex& new_simplex) const {
  // A substitution v → w: w is new in the element, and either the only new vertex or a copy
  // of v (parents = {v}, as dissect makes them).
  std::vector<VertexId> gone, came;
  for (VertexId v : old_simplex.vertices())
    if (!new_simplex.contains(v)) gone.push_back(v);
  for (VertexId w : new_simplex.vertices())
    if (!old_simplex.contains(w)) came.push_back(w);
  TaggedSimplex label = old_label;
  for (int i = 0; i <= label.dim; ++i) {
    const auto g = std::find(gone.begin(), gone.end(), label.vertex[i]);
    if (g == gone.end()) continue;
    VertexId image = no_id;
    if (gone.size() == 1) {
      image = came.front();
    } else {
      for (VertexId w : came) {
        const VertexParents parents = mesh_.parents(w);
        if (parents.count() == 1 && parents.vertex[0] == *g) image = w;
      }
    }
    if (image == no_id) return initial_labelling(mesh_, new_simplex, rule_);
    label.vertex[i] = image;
  }
  return label;
}

void RefinementHierarchy::on_change(const Connectivity& connectivity, const ConnectivityChange& change) {
  for (const auto& [e, simplex] : change.removed_elements) {
    nodes_[node_of_element_[e]].element = no_id;
    node_of_element_[e] = no_id;
  }
  if (!expected_.empty()) {
    if (change.added_elements.size() != 2 * expected_.size())
      throw std::logic_error("refinement hierarchy: a split added " + std::to_string(change.added_elements.size()) +
                             " elements for " + std::to_string(expected_.size()) + " announced splits");
    for (std::size_t i = 0; i < expected_.size(); ++i) {
      const ExpectedSplit& split = expected_[i];
      for (int c = 0; c < 2; ++c)
        nodes_[split.parent].children[c] = add_node(split.children[c], split.parent, change.added_elements[2 * i + c]);
    }
    expected_.clear();
  } else {
    for (ElementId e : change.added_elements) add_root(initial_labelling(mesh_, connectivity.element(e).simplex, rule_), e);
  }
  for (const auto& [e, old_simplex] : change.changed_elements) {
    const NodeId old_node = node_of_element_[e];
    const TaggedSimplex label = relabelled(nodes_[old_node].label, old_simplex, connectivity.element(e).simplex);
    nodes_[old_node].element = no_id;
    add_root(label, e);
  }
  // A root's box follows its vertices: a moved vertex, or a removed one whose id comes back
  // elsewhere, makes the grid stale.
  for (const VertexEvent& event : change.vertex_events)
    if (event.kind != VertexEventKind::added || event.vertex < n_points_seen_) root_grid_.clear();
  n_points_seen_ = mesh_.n_points();
}

BoundingBox RefinementHierarchy::padded_box(NodeId root) const {
  const TaggedSimplex& label = nodes_[root].label;
  const int d = label.dim;
  BoundingBox box;
  double size = 0;
  for (int k = 0; k < d; ++k) {
    box.lo[k] = box.hi[k] = mesh_.point(label.vertex[0])[k];
    for (int i = 1; i <= d; ++i) {
      box.lo[k] = std::min(box.lo[k], mesh_.point(label.vertex[i])[k]);
      box.hi[k] = std::max(box.hi[k], mesh_.point(label.vertex[i])[k]);
    }
    size = std::max(size, box.hi[k] - box.lo[k]);
  }
  // A point on_face_tolerance outside in barycentric terms is at most that times the simplex's
  // diameter (√d · size) away: the padding is far wider.
  for (int k = 0; k < d; ++k) {
    box.lo[k] -= 1e3 * on_face_tolerance * size;
    box.hi[k] += 1e3 * on_face_tolerance * size;
  }
  return box;
}

std::array<double, max_dimension + 1> RefinementHierarchy::barycentric(const TaggedSimplex& label,
                                                                       std::span<const double> x) const {
  const int d = label.dim;
  const auto coordinate = [&](VertexId v, int k) { return mesh_.points()[static_cast<std::size_t>(v) * d + k]; };
  Eigen::Matrix3d edges = Eigen::Matrix3d::Identity();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int k = 0; k < d; ++k) {
    for (int i = 1; i <= d; ++i) edges(k, i - 1) = coordinate(label.vertex[i], k) - coordinate(label.vertex[0], k);
    rhs(k) = x[k] - coordinate(label.vertex[0], k);
  }
  const Eigen::Vector3d mu = edges.partialPivLu().solve(rhs);
  std::array<double, max_dimension + 1> lambda{};
  lambda[0] = 1;
  for (int i = 1; i <= d; ++i) {
    lambda[i] = mu(i - 1);
    lambda[0] -= mu(i - 1);
  }
  return lambda;
}

std::vector<NodeId> RefinementHierarchy::roots_containing(std::span<const double> x) const {
  if (mesh_.is_surface())
    throw std::invalid_argument("point location needs a volume mesh (triangles in 2D or tetrahedra); this is a surface");
  if (x.size() != static_cast<std::size_t>(mesh_.dim()))
    throw std::invalid_argument("locate: the point has " + std::to_string(x.size()) + " coordinates, the mesh is " +
                                std::to_string(mesh_.dim()) + "-D");
  if (!root_grid_.built() || root_grid_.n_added() > root_grid_.n_built() / 4)
    root_grid_.build(mesh_.dim(), roots_, [this](NodeId r) { return padded_box(r); });
  std::vector<NodeId> found;
  for (NodeId r : root_grid_.candidates(x)) {
    const auto lambda = barycentric(nodes_[r].label, x);
    if (*std::min_element(lambda.begin(), lambda.begin() + mesh_.dim() + 1) >= -on_face_tolerance) found.push_back(r);
  }
  std::sort(found.begin(), found.end());  // in the order of roots_, as a scan finds them
  return found;
}

std::vector<NodeId> RefinementHierarchy::roots_meeting(const BoundingBox& box) const {
  if (mesh_.is_surface()) return roots_;  // the grid's boxes span the cells' own dimensions
  if (!root_grid_.built() || root_grid_.n_added() > root_grid_.n_built() / 4)
    root_grid_.build(mesh_.dim(), roots_, [this](NodeId r) { return padded_box(r); });
  return root_grid_.candidates(box);
}

std::vector<ElementId> RefinementHierarchy::locate_all(std::span<const double> x, std::span<const NodeId> roots) const {
  std::vector<ElementId> found;
  std::vector<NodeId> stack(roots.begin(), roots.end());
  while (!stack.empty()) {
    const RefinementNode& node = nodes_[stack.back()];
    stack.pop_back();
    if (node.is_leaf()) {
      if (node.element != no_id) found.push_back(node.element);
      continue;
    }
    // The bisecting hyperplane is where x0 and xk have equal barycentric weight (§6.5's BSP).
    const auto lambda = barycentric(node.label, x);
    const double side = lambda[0] - lambda[node.label.tag];
    if (side >= -on_face_tolerance) stack.push_back(node.children[0]);
    if (side <= on_face_tolerance) stack.push_back(node.children[1]);
  }
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<ElementId> RefinementHierarchy::locate_all(std::span<const double> x) const {
  return locate_all(x, roots_containing(x));
}

ElementId RefinementHierarchy::locate(std::span<const double> x) const {
  const std::vector<ElementId> found = locate_all(x);
  return found.empty() ? no_id : found.front();
}

std::size_t RefinementHierarchy::memory_bytes() const {
  return nodes_.capacity() * sizeof(RefinementNode) + roots_.capacity() * sizeof(NodeId) +
         node_of_element_.capacity() * sizeof(NodeId);
}

}  // namespace snede
