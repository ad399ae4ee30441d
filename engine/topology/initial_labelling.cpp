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

TaggedSimplex longest_edge_triangle(const Mesh& mesh, const Simplex& element) {
  // The apex is the vertex opposite the longest edge; total order: length, then vertex ids.
  auto edge_key = [&](int apex) {
    const VertexId a = element.vertex((apex + 1) % 3), b = element.vertex((apex + 2) % 3);
    return std::make_tuple(squared_distance(mesh, a, b), std::max(a, b), std::min(a, b));
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

}  // namespace

TaggedSimplex initial_labelling(const Mesh& mesh, const Simplex& element) {
  if (mesh.cell_dim() == 2) return longest_edge_triangle(mesh, element);
  TaggedSimplex t;
  t.dim = 3;
  t.tag = 3;
  std::copy(element.vertices().begin(), element.vertices().end(), t.vertex.begin());  // already sorted (§7.2)
  return t;
}

}  // namespace snede
