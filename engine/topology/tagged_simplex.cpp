#include "topology/tagged_simplex.hpp"

#include <stdexcept>

namespace snede {

bool TaggedSimplex::contains(VertexId v) const {
  for (int i = 0; i <= dim; ++i)
    if (vertex[i] == v) return true;
  return false;
}

bool TaggedSimplex::has_refinement_edge(VertexId a, VertexId b) const {
  const VertexId p = refinement_start(), q = refinement_end();
  return (p == a && q == b) || (p == b && q == a);
}

TaggedSimplex TaggedSimplex::with_refinement_edge(VertexId a, VertexId b) const {
  TaggedSimplex t = *this;
  t.tag = static_cast<std::int8_t>(dim);
  int k = 1;
  for (int i = 0; i <= dim; ++i)
    if (vertex[i] != a && vertex[i] != b) t.vertex[k++] = vertex[i];
  if (k != dim) throw std::invalid_argument("with_refinement_edge: (a, b) is not an edge of the simplex");
  t.vertex[0] = a;
  t.vertex[dim] = b;
  return t;
}

std::array<TaggedSimplex, 2> TaggedSimplex::children(VertexId midpoint) const {
  const auto child_tag = static_cast<std::int8_t>(tag > 1 ? tag - 1 : dim);
  TaggedSimplex keeps_start = *this, keeps_end = *this;
  keeps_start.vertex[tag] = midpoint;
  for (int i = 0; i < tag; ++i) keeps_end.vertex[i] = vertex[i + 1];
  keeps_end.vertex[tag] = midpoint;
  keeps_start.tag = keeps_end.tag = child_tag;
  return {keeps_start, keeps_end};
}

}  // namespace snede
