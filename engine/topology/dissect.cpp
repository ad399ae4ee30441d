#include "topology/dissect.hpp"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "mesh/traversal.hpp"

namespace snede {

std::vector<SplitVertex> dissect(Connectivity& c, std::span<const FaceId> cut_faces,
                                 const std::function<VertexId(VertexId)>& new_vertex) {
  std::unordered_set<FaceId> cut;  // C, closed under mate
  std::unordered_map<VertexId, ElementId> start_of;  // each vertex of C with an element containing it
  for (FaceId f : cut_faces) {
    if (!c.is_face(f)) throw std::invalid_argument("dissect: face " + std::to_string(f) + " does not exist");
    const Face& face = c.face(f);
    if (face.mate == no_id)
      throw std::invalid_argument("dissect: face " + face.simplex.to_string() + " lies on the boundary");
    cut.insert(f);
    cut.insert(face.mate);
    for (VertexId v : face.simplex.vertices()) start_of.emplace(v, face.element);
  }
  std::vector<VertexId> vertices;
  for (const auto& entry : start_of) vertices.push_back(entry.first);
  std::sort(vertices.begin(), vertices.end());  // deterministic numbering of the copies

  std::unordered_map<ElementId, ElementSubstitution> substitution;
  std::vector<SplitVertex> split;
  for (VertexId v : vertices) {
    const std::vector<ElementId> star = vertex_star(c, v, start_of[v]);
    // Classes of (v, C)-connectedness: walk within the star without crossing C.
    std::unordered_map<ElementId, int> class_of;
    int n_classes = 0;
    for (ElementId seed : star) {
      if (class_of.count(seed)) continue;
      std::vector<ElementId> stack{seed};
      class_of[seed] = n_classes;
      while (!stack.empty()) {
        const ElementId e = stack.back();
        stack.pop_back();
        const Element& element = c.element(e);
        for (int j = 0; j <= c.dim(); ++j) {
          if (element.simplex.vertex(j) == v || cut.count(element.faces[j])) continue;
          const ElementId next = c.neighbor(e, j);
          if (next != no_id && !class_of.count(next)) {
            class_of[next] = n_classes;
            stack.push_back(next);
          }
        }
      }
      ++n_classes;
    }
    std::vector<VertexId> copy_of_class(n_classes, v);
    for (int k = 1; k < n_classes; ++k) {
      copy_of_class[k] = new_vertex(v);
      split.push_back({v, copy_of_class[k]});
    }
    for (const auto& [e, k] : class_of) {
      if (k == 0) continue;
      auto [it, inserted] = substitution.try_emplace(e, ElementSubstitution{e, {}});
      it->second.from_to.emplace_back(v, copy_of_class[k]);
    }
  }
  std::vector<ElementSubstitution> list;
  list.reserve(substitution.size());
  for (auto& entry : substitution) list.push_back(std::move(entry.second));
  std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.element < b.element; });
  c.change_elements(list);
  return split;
}

std::vector<SplitVertex> dissect(Mesh& mesh, const std::vector<VertexId>& face_vertices) {
  const std::vector<FaceId> faces = mesh.find_faces(face_vertices);
  return dissect(mesh.connectivity(), faces,
                 [&mesh](VertexId original) { return mesh.add_vertex(VertexParents::copy_of(original)); });
}

}  // namespace snede
