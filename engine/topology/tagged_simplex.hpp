// A simplex labelled for Maubach's bisection ([62], §6.5): its vertices in an order x0..xd
// and a tag k in 1..d. The refinement edge is x0–xk. In 2D this is newest-vertex bisection:
// the refinement edge of a child is the edge opposite the midpoint that created it.
#pragma once

#include <array>
#include <cstdint>
#include <utility>

#include "mesh/simplex.hpp"

namespace snede {

struct TaggedSimplex {
  std::array<VertexId, max_dimension + 1> vertex{};  // x0..xd; only the first dim + 1 are used
  std::int8_t dim = 0;
  std::int8_t tag = 0;  // k in 1..dim

  VertexId refinement_start() const { return vertex[0]; }
  VertexId refinement_end() const { return vertex[tag]; }
  bool contains(VertexId v) const;
  bool has_refinement_edge(VertexId a, VertexId b) const;
  // Maubach's children when x0–xk is bisected at `midpoint`: first the child keeping x0
  // (x0..x_{k-1}, z, x_{k+1}..x_d), then the one keeping xk (x1..x_k, z, x_{k+1}..x_d); both
  // have tag k − 1, or d after tag 1. Every d generations the cycle of tags repeats, which is
  // what bounds the number of similarity classes.
  std::array<TaggedSimplex, 2> children(VertexId midpoint) const;
  // The same simplex relabelled so that (a, b), one of its edges, is the refinement edge:
  // x0 = a, xd = b, the others in their current order, tag d.
  TaggedSimplex with_refinement_edge(VertexId a, VertexId b) const;
};

}  // namespace snede
