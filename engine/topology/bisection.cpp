#include "topology/bisection.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "mesh/traversal.hpp"

namespace snede {

Bisection::Bisection(Mesh& mesh, std::optional<BisectionRule> rule, std::vector<TaggedSimplex> root_labels)
    : mesh_(mesh), hierarchy_(mesh, rule, std::move(root_labels)) {}

std::vector<ElementId> Bisection::around_edge(VertexId a, VertexId b, ElementId start) const {
  if (rings_) {
    std::vector<ElementId> found = rings_->around(a, b);
    if (!found.empty()) return found;
  }
  return elements_around(mesh_.connectivity(), Simplex(1, {a, b}), start);
}

ElementId Bisection::live_element_with_edge(NodeId node, VertexId a, VertexId b) const {
  while (!hierarchy_.node(node).is_leaf()) {
    const RefinementNode& parent = hierarchy_.node(node);
    const TaggedSimplex& first = hierarchy_.node(parent.children[0]).label;
    node = first.contains(a) && first.contains(b) ? parent.children[0] : parent.children[1];
  }
  const ElementId e = hierarchy_.node(node).element;
  if (e == no_id)
    throw std::runtime_error("bisection: the element holding edge (" + std::to_string(a) + ", " + std::to_string(b) +
                             ") was removed by another mesh operation");
  return e;
}

std::size_t Bisection::simple_bisect(VertexId a, VertexId b, const std::vector<ElementId>& around) {
  const VertexId midpoint = mesh_.add_vertex(VertexParents::on_edge(a, b, 0.5));  // before replace_elements: watchers see it
  const Connectivity& c = mesh_.connectivity();
  std::vector<Simplex> halves;
  halves.reserve(2 * around.size());
  for (ElementId e : around) {
    TaggedSimplex label = hierarchy_.label(e);
    if (!label.has_refinement_edge(a, b)) label = label.with_refinement_edge(a, b);
    const Simplex& whole = c.element(e).simplex;
    // Substituting one endpoint keeps the orientation, so both halves stay positive.
    halves.push_back(whole.substituted(label.refinement_end(), midpoint));
    halves.push_back(whole.substituted(label.refinement_start(), midpoint));
    hierarchy_.expect_split(e, labels_of_halves(mesh_, label, midpoint, hierarchy_.rule()));
  }
  mesh_.connectivity().replace_elements(around, halves);
  return around.size();
}

std::size_t Bisection::bisect(ElementId element) {
  // Far more than a compatible labelling needs (a few per level of difference).
  constexpr std::size_t max_pending = 10000;
  const TaggedSimplex& label = hierarchy_.label(element);
  std::vector<EdgeToBisect> pending{{label.refinement_start(), label.refinement_end(), hierarchy_.node_of(element)}};
  std::size_t n_split = 0;
  while (!pending.empty()) {
    const EdgeToBisect edge = pending.back();
    const ElementId start = live_element_with_edge(edge.node, edge.a, edge.b);
    const std::vector<ElementId> around = around_edge(edge.a, edge.b, start);
    const auto other = std::find_if(around.begin(), around.end(), [&](ElementId e) {
      return !hierarchy_.label(e).has_refinement_edge(edge.a, edge.b);
    });
    if (other == around.end()) {
      n_split += simple_bisect(edge.a, edge.b, around);
      pending.pop_back();
      continue;
    }
    // §6.5: first bisect the neighbour's own refinement edge.
    const TaggedSimplex& neighbour = hierarchy_.label(*other);
    const EdgeToBisect first{neighbour.refinement_start(), neighbour.refinement_end(), hierarchy_.node_of(*other)};
    const bool cycles = std::any_of(pending.begin(), pending.end(), [&](const EdgeToBisect& p) {
      return std::minmax(p.a, p.b) == std::minmax(first.a, first.b);
    });
    if (cycles || pending.size() >= max_pending) {
      // Forced (see bisect's comment): the requested edge itself, now. Forcing an edge higher
      // up the stack instead can leave the next one cycling again, without end.
      const EdgeToBisect requested = pending.front();
      const ElementId holder = live_element_with_edge(requested.node, requested.a, requested.b);
      n_split += simple_bisect(requested.a, requested.b, around_edge(requested.a, requested.b, holder));
      ++n_forced_splits_;
      break;
    }
    pending.push_back(first);
  }
  return n_split;
}

std::size_t Bisection::refine_uniform(int levels) {
  if (levels < 0) throw std::invalid_argument("refine_uniform: levels must be ≥ 0, got " + std::to_string(levels));
  ChangeBatch batch(mesh_.connectivity());  // watchers reissue sizes once
  std::size_t n_split = 0;
  for (int level = 0; level < levels; ++level) {
    std::vector<NodeId> unsplit;
    for (ElementId e : mesh_.connectivity().element_ids()) unsplit.push_back(hierarchy_.node_of(e));
    for (NodeId n : unsplit) {
      const RefinementNode& node = hierarchy_.node(n);
      if (node.is_leaf() && node.element != no_id) n_split += bisect(node.element);
    }
  }
  return n_split;
}

}  // namespace snede
