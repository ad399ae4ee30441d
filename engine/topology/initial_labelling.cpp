#include "topology/initial_labelling.hpp"

#include <algorithm>
#include <tuple>

namespace snede {
namespace {

double squared_distance(const Mesh& mesh, VertexId a, VertexId b) {
  if (b < a) std::swap(a, b);  // the same rounding from both elements sharing the edge
  double sum = 0;
  for (int k = 0; k < mesh.dim(); ++k) {
    const double d = mesh.points()[static_cast<std::size_t>(b) * mesh.dim() + k] -
                     mesh.points()[static_cast<std::size_t>(a) * mesh.dim() + k];
    sum += d * d;
  }
  return sum;
}

// The strict total order on edges of the longest-edge rules: length, then vertex ids.
std::tuple<double, VertexId, VertexId> edge_order(const Mesh& mesh, VertexId a, VertexId b) {
  return std::make_tuple(squared_distance(mesh, a, b), std::max(a, b), std::min(a, b));
}

TaggedSimplex longest_edge_triangle(const Mesh& mesh, const Simplex& element) {
  // The apex is the vertex opposite the longest edge.
  auto edge_key = [&](int apex) {
    return edge_order(mesh, element.vertex((apex + 1) % 3), element.vertex((apex + 2) % 3));
  };
  int apex = 0;
  for (int i = 1; i < 3; ++i)
    if (edge_key(i) > edge_key(apex)) apex = i;
  const VertexId a = element.vertex((apex + 1) % 3), b = element.vertex((apex + 2) % 3);
  TaggedSimplex t;
  t.dim = 2;
  t.tag = 2;
  t.vertex = {std::min(a, b), element.vertex(apex), std::max(a, b), 0};
  return t;
}

// The longest edge of a tetrahedron as its endpoints' positions in `t`.
std::pair<int, int> longest_edge_of(const Mesh& mesh, const TaggedSimplex& t) {
  std::pair<int, int> longest{0, 1};
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (edge_order(mesh, t.vertex[i], t.vertex[j]) > edge_order(mesh, t.vertex[longest.first], t.vertex[longest.second]))
        longest = {i, j};
  return longest;
}

TaggedSimplex sorted_tetrahedron(const Simplex& element) {
  TaggedSimplex t;
  t.dim = 3;
  t.tag = 3;
  std::copy(element.vertices().begin(), element.vertices().end(), t.vertex.begin());  // already sorted (§7.2)
  return t;
}

TaggedSimplex longest_edge_tetrahedron(const Mesh& mesh, const TaggedSimplex& t) {
  const auto [i, j] = longest_edge_of(mesh, t);
  return t.with_refinement_edge(std::min(t.vertex[i], t.vertex[j]), std::max(t.vertex[i], t.vertex[j]));
}

}  // namespace

BisectionRule bisection_rule_for(const Mesh& mesh) {
  if (mesh.cell_dim() != 3) return BisectionRule::newest_vertex;
  const Connectivity& c = mesh.connectivity();
  for (ElementId e : c.element_ids()) {
    const TaggedSimplex sorted = sorted_tetrahedron(c.element(e).simplex);
    if (longest_edge_of(mesh, sorted) != std::pair<int, int>{0, 3}) return BisectionRule::longest_edge;
  }
  return BisectionRule::newest_vertex;
}

TaggedSimplex initial_labelling(const Mesh& mesh, const Simplex& element, BisectionRule rule) {
  if (mesh.cell_dim() == 2) return longest_edge_triangle(mesh, element);
  const TaggedSimplex sorted = sorted_tetrahedron(element);
  return rule == BisectionRule::longest_edge ? longest_edge_tetrahedron(mesh, sorted) : sorted;
}

std::array<TaggedSimplex, 2> labels_of_halves(const Mesh& mesh, const TaggedSimplex& label, VertexId midpoint,
                                              BisectionRule rule) {
  std::array<TaggedSimplex, 2> halves = label.children(midpoint);
  if (rule == BisectionRule::longest_edge && label.dim == 3)
    for (TaggedSimplex& half : halves) half = longest_edge_tetrahedron(mesh, half);
  return halves;
}

}  // namespace snede
