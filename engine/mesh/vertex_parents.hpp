// Where a vertex added or moved by a mesh operation sits: a weighted sum of existing vertices
// (barycentric coordinates in an element, a face or an edge). Its coordinates, and in a model
// its displacement, are interpolated from the parents' (§7.4: watchers carry fields over).
#pragma once

#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh/simplex.hpp"

namespace snede {

struct VertexParents {
  std::vector<VertexId> vertex;
  std::vector<double> weight;  // same length as vertex; sums to 1

  std::size_t count() const { return vertex.size(); }
  // One parent with weight 1: a copy (dissection) of v.
  static VertexParents copy_of(VertexId v) { return {{v}, {1.0}}; }
  // The point (1 − t)·a + t·b on edge (a, b).
  static VertexParents on_edge(VertexId a, VertexId b, double t) { return {{a, b}, {1.0 - t, t}}; }
  // Barycentric coordinates: weights[i] of vertices[i]. Throws std::invalid_argument unless
  // the lengths agree, every weight is finite and the weights sum to 1 (to 1e-12).
  static VertexParents barycentric(std::span<const VertexId> vertices, std::span<const double> weights);
};

// What happened to one vertex within a change, in the order it happened.
enum class VertexEventKind : std::uint8_t { added, moved, removed };

struct VertexEvent {
  VertexEventKind kind;
  VertexId vertex;
  // added/moved: where the vertex now is, in terms of the vertices as they were just before
  // this event (a moved vertex may be its own parent). Empty for a removed vertex, and for a
  // vertex moved to explicit coordinates (its fields are then kept, not interpolated).
  VertexParents parents;
};

// Replays `events` on a field of `components` numbers per vertex (values has a row for every
// vertex id the events name): an added or moved vertex takes its parents' values as they were
// just before its event; an added vertex without parents, or a removed one, gets zeros; a
// vertex moved to explicit coordinates keeps its values (§7.4: watchers carry fields over).
void replay_vertex_events(std::span<double> values, int components, std::span<const VertexEvent> events);

}  // namespace snede
