// Cuts along a plane section of a mesh with integer coordinates (Kuhn boxes), shared by the tests
// of the pieces a cut makes: a section's interior faces, a notch of it near one edge, and their
// dissection (each new lip vertex a copy of the one it was cut from).
#pragma once

#include <utility>
#include <vector>

#include "mesh/mesh.hpp"
#include "topology/dissect.hpp"

namespace snede::testing {

// Interior faces (one of each mate pair) whose vertices all have coordinate `axis` = value.
inline std::vector<FaceId> faces_in_plane(const Mesh& mesh, int axis, double value) {
  const Connectivity& c = mesh.connectivity();
  std::vector<FaceId> faces;
  for (FaceId f = 0; f < c.face_capacity(); ++f) {
    if (!c.is_face(f) || c.face(f).mate == no_id || c.face(f).mate < f) continue;
    bool in = true;
    for (VertexId v : c.face(f).simplex.vertices()) in = in && mesh.point(v)[axis] == value;
    if (in) faces.push_back(f);
  }
  return faces;
}

inline void dissect_faces(Mesh& mesh, const std::vector<FaceId>& faces) {
  dissect(mesh.connectivity(), faces, [&mesh](VertexId v) { return mesh.add_vertex(VertexParents::copy_of(v)); });
}

// The interior faces of the section x = value, as a notch (those within one cell of the edge
// y = z = 0) and the rest.
inline std::pair<std::vector<FaceId>, std::vector<FaceId>> notch_and_rest(const Mesh& mesh, double value) {
  std::vector<FaceId> notch, rest;
  for (FaceId f : faces_in_plane(mesh, 0, value)) {
    bool near = true;
    for (VertexId v : mesh.connectivity().face(f).simplex.vertices())
      near = near && mesh.point(v)[1] <= 1 && mesh.point(v)[2] <= 1;
    (near ? notch : rest).push_back(f);
  }
  return {notch, rest};
}

}  // namespace snede::testing
