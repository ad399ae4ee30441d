#include "topology/tagged_simplex.hpp"

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
