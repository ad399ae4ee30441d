// Walking the connectivity: around a (d-2)-simplex (§7.2 cycle-around), stars of vertices
// and of any simplex, boundary faces, connected components.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesh/connectivity.hpp"

namespace snede {

// §7.2 cycle-around: the elements containing σ = entry.simplex.subn(j), in the order met
// when walking from face to mate around σ. Where the walk reaches the boundary it also walks
// the other way from entry's mate, so the result is the whole ring around σ (in order along
// the ring, starting at one boundary end when σ is on the boundary).
std::vector<ElementId> cycle_around(const Connectivity& c, FaceId entry, int j);

// All elements containing every vertex of `s`, found by walking across faces that contain
// `s`, starting from `start` (which must contain s). For a vertex this is its star.
std::vector<ElementId> elements_around(const Connectivity& c, const Simplex& s, ElementId start);

// The star of vertex v (§7.3): with a start element, the elements reached by walking across
// faces that contain v (the (v, ∅)-connected part); without one, every element containing v,
// found by a scan (O(n)). Empty if no element contains v.
std::vector<ElementId> vertex_star(const Connectivity& c, VertexId v, ElementId start = no_id);

// Every vertex's star at once, as one flat array (CSR) — what whole-mesh loops over vertex
// neighbourhoods (assembled matrices' sparsity, coarse spaces) rebuild after every edit.
struct VertexStars {
  std::vector<ElementId> elements;                               // live elements, by id
  std::vector<std::array<VertexId, max_dimension + 1>> vertices;  // per element: oriented vertices
  std::vector<std::size_t> start;                                // per vertex id: its first entry
  std::vector<std::uint32_t> entries;                            // (element index << 2) | corner
  std::size_t element_of(std::uint32_t entry) const { return entry >> 2; }
  int corner_of(std::uint32_t entry) const { return static_cast<int>(entry & 3u); }
};
VertexStars all_vertex_stars(const Connectivity& c, VertexId n_points);

// Face ids of the boundary faces, sorted by their simplex (deterministic order).
std::vector<FaceId> boundary_faces(const Connectivity& c);

// Component label per element id (no_id for free slots), components being classes of
// elements joined through faces; second member is the number of components.
std::pair<std::vector<int>, int> connected_components(const Connectivity& c);

}  // namespace snede
