#include "mesh/validate.hpp"

#include <unordered_map>
#include <unordered_set>

namespace snede {
namespace {

std::string face_text(const Connectivity& c, FaceId f) {
  return "face " + std::to_string(f) + " " + c.face(f).simplex.to_string();
}

std::string element_text(const Connectivity& c, ElementId e) {
  return "element " + std::to_string(e) + " " + c.element(e).simplex.to_string();
}

}  // namespace

std::optional<std::string> find_violation(const Connectivity& c) {
  const int d = c.dim();
  std::size_t n_live = 0;
  std::unordered_map<Simplex, ElementId, SimplexHash> element_by_vertices;  // (7.4), orientation ignored
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    ++n_live;
    const Element& element = c.element(e);
    if (element.simplex.dimension() != d)
      return element_text(c, e) + " has dimension " + std::to_string(element.simplex.dimension()) +
             ", the mesh has " + std::to_string(d);
    const Simplex unsigned_key = element.simplex.sign() > 0 ? element.simplex : element.simplex.mate();
    if (auto [it, inserted] = element_by_vertices.emplace(unsigned_key, e); !inserted)
      return "(7.4) " + element_text(c, e) + " and " + element_text(c, it->second) + " have the same vertices";
    for (int j = 0; j <= d; ++j) {
      const FaceId f = element.faces[j];
      if (!c.is_face(f))
        return element_text(c, e) + ": faces[" + std::to_string(j) + "] = " + std::to_string(f) +
               " is not a live face";
      if (c.face(f).simplex != element.simplex.subn(j))
        return "(7.1) " + element_text(c, e) + ": faces[" + std::to_string(j) + "] is " + face_text(c, f) +
               ", expected " + element.simplex.subn(j).to_string();
      if (c.face(f).element != e)
        return "(7.2) " + face_text(c, f) + " is faces[" + std::to_string(j) + "] of " + element_text(c, e) +
               " but points to element " + std::to_string(c.face(f).element);
    }
  }
  if (n_live != c.n_elements())
    return "element count " + std::to_string(c.n_elements()) + " but " + std::to_string(n_live) + " live elements";

  std::unordered_map<Simplex, FaceId, SimplexHash> face_by_simplex;
  std::size_t n_faces = 0;
  for (FaceId f = 0; f < c.face_capacity(); ++f) {
    if (!c.is_face(f)) continue;
    ++n_faces;
    const Face& face = c.face(f);
    if (!c.is_element(face.element)) return "(7.2) " + face_text(c, f) + " points to a dead element";
    bool listed = false;
    for (int j = 0; j <= d; ++j) listed |= c.element(face.element).faces[j] == f;
    if (!listed) return "(7.2) " + face_text(c, f) + " is not among the faces of " + element_text(c, face.element);
    if (auto [it, inserted] = face_by_simplex.emplace(face.simplex, f); !inserted)
      return "(7.4) " + face_text(c, f) + " and face " + std::to_string(it->second) + " have the same simplex";
    if (face.mate != no_id) {
      if (!c.is_face(face.mate)) return "(7.3) " + face_text(c, f) + " has a dead mate " + std::to_string(face.mate);
      if (c.face(face.mate).simplex != face.simplex.mate())
        return "(7.3) " + face_text(c, f) + " has mate " + face_text(c, face.mate) + ", not its opposite";
      if (c.face(face.mate).mate != f)
        return "(7.3) " + face_text(c, f) + " has mate " + face_text(c, face.mate) + " whose mate is " +
               std::to_string(c.face(face.mate).mate);
    }
  }
  if (n_faces != (d + 1) * c.n_elements())
    return std::to_string(n_faces) + " live faces for " + std::to_string(c.n_elements()) + " elements of " +
           std::to_string(d + 1) + " faces";

  // (7.5): the boundary map holds exactly the unmatched faces, and no unmatched face has an
  // opposite that exists (that would be a pair that forgot to link).
  for (const auto& [sigma, f] : c.boundary()) {
    if (!c.is_face(f)) return "(7.5) boundary entry " + sigma.to_string() + " points to dead face " + std::to_string(f);
    if (c.face(f).simplex != sigma)
      return "(7.5) boundary entry " + sigma.to_string() + " points to " + face_text(c, f);
    if (c.face(f).mate != no_id) return "(7.5) boundary " + face_text(c, f) + " has a mate";
  }
  for (const auto& [sigma, f] : face_by_simplex) {
    if (c.face(f).mate != no_id) continue;
    if (!c.boundary().count(sigma)) return "(7.5) " + face_text(c, f) + " has no mate but is not in the boundary map";
    if (auto opposite = face_by_simplex.find(sigma.mate()); opposite != face_by_simplex.end())
      return "(7.5) " + face_text(c, f) + " is on the boundary but its opposite " +
             face_text(c, opposite->second) + " exists";
  }
  // Vertex incidences: exact use counts, and a hint that is an element containing the vertex.
  std::unordered_map<VertexId, std::int32_t> uses;
  for (ElementId e : c.element_ids())
    for (VertexId v : c.element(e).simplex.vertices()) ++uses[v];
  for (const auto& [v, n] : uses) {
    if (c.n_vertex_uses(v) != n)
      return "vertex " + std::to_string(v) + " is used by " + std::to_string(n) + " elements but counted " +
             std::to_string(c.n_vertex_uses(v));
    const ElementId hint = c.vertex_element(v);
    if (!c.is_element(hint) || !c.element(hint).simplex.contains(v))
      return "vertex " + std::to_string(v) + " names element " + std::to_string(hint) + ", which does not contain it";
  }
  return std::nullopt;
}

}  // namespace snede
