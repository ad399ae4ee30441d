#include "fem/strain_patches.hpp"

#include <algorithm>

namespace snede {

template <int D>
void StrainPatches<D>::build(const ElementStream<D>& stream, VertexId n_points) {
  static std::uint64_t builds = 0;  // across all patch sets: a rebuilt body never matches an old key
  generation_ = ++builds;
  const ElementId capacity = stream.capacity();
  // Vertex stars (CSR over vertex ids), elements in id order.
  vertex_start_.assign(static_cast<std::size_t>(n_points) + 1, 0);
  vertex_measure_.assign(n_points, 0.0);
  for (ElementId e = 0; e < capacity; ++e)
    if (stream.is_live(e))
      for (VertexId v : stream.vertices(e)) ++vertex_start_[v + 1];
  for (VertexId v = 0; v < n_points; ++v) vertex_start_[v + 1] += vertex_start_[v];
  vertex_element_list_.resize(vertex_start_.back());
  std::vector<std::size_t> fill(vertex_start_.begin(), vertex_start_.end() - 1);
  for (ElementId e = 0; e < capacity; ++e) {
    if (!stream.is_live(e)) continue;
    const double share = stream.reference(e).measure * vertex_share;
    for (VertexId v : stream.vertices(e)) {
      vertex_element_list_[fill[v]++] = e;
      vertex_measure_[v] += share;
    }
  }
  // Edge patches: vertex by vertex, the edges to higher vertices of its star, each numbered
  // the first time it is met (a scratch place per vertex instead of a hash of pairs).
  element_edges_.assign(capacity, {});
  for (auto& edges : element_edges_) edges.fill(-1);
  edge_measure_.clear();
  std::vector<std::int32_t> place(n_points, -1);
  std::vector<VertexId> touched;
  for (VertexId v = 0; v < n_points; ++v) {
    for (ElementId e : vertex_elements(v)) {
      const auto vertices = stream.vertices(e);
      const double share = stream.reference(e).measure * edge_share;
      const auto edges = local_edges();
      for (int k = 0; k < edges_per_element; ++k) {
        const VertexId a = vertices[edges[k][0]], b = vertices[edges[k][1]];
        if (std::min(a, b) != v) continue;
        const VertexId w = std::max(a, b);
        if (place[w] < 0) {
          place[w] = static_cast<std::int32_t>(edge_measure_.size());
          edge_measure_.push_back(0.0);
          touched.push_back(w);
        }
        element_edges_[e][k] = place[w];
        edge_measure_[place[w]] += share;
      }
    }
    for (VertexId w : touched) place[w] = -1;
    touched.clear();
  }
  edge_start_.assign(edge_measure_.size() + 1, 0);
  for (ElementId e = 0; e < capacity; ++e)
    if (stream.is_live(e))
      for (std::int32_t k : element_edges_[e]) ++edge_start_[k + 1];
  for (std::size_t k = 0; k < edge_measure_.size(); ++k) edge_start_[k + 1] += edge_start_[k];
  edge_element_list_.resize(edge_start_.back());
  fill.assign(edge_start_.begin(), edge_start_.end() - 1);
  for (ElementId e = 0; e < capacity; ++e)
    if (stream.is_live(e))
      for (std::int32_t k : element_edges_[e]) edge_element_list_[fill[k]++] = e;
}

template class StrainPatches<2>;
template class StrainPatches<3>;

}  // namespace snede
