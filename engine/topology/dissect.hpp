// §7.3 dissect: cutting along a set of face pairs C, as one change_elements call.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

struct SplitVertex {
  VertexId original;
  VertexId copy;
};

// Cuts along C = the given interior faces and their mates. For every vertex v of C, star(v)
// is partitioned into (v, C)-connected classes (Figures 7.6–7.7); the class containing the
// first element found keeps v, every other class gets a vertex from `new_vertex(v)`.
// Faces of C whose vertices' stars do not split stay joined (Figure 7.7).
// Throws std::invalid_argument for a face that does not exist or lies on the boundary.
std::vector<SplitVertex> dissect(Connectivity& c, std::span<const FaceId> cut_faces,
                                 const std::function<VertexId(VertexId)>& new_vertex);

// The same on a mesh, faces given by their vertices ((n, cell_dim), either orientation); the
// copies are new vertices with their original as only parent (same coordinates and fields).
std::vector<SplitVertex> dissect(Mesh& mesh, const std::vector<VertexId>& face_vertices);

}  // namespace snede
