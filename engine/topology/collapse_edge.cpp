#include "topology/collapse_edge.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <set>

#include "topology/local_star.hpp"
#include "topology/orientation_checks.hpp"

namespace snede {
namespace {

// Stands for "outside the mesh": joined to every boundary face, it closes the mesh off so
// that the link condition also covers vertices and edges on the boundary.
constexpr VertexId virtual_vertex = std::numeric_limits<VertexId>::max();

// A link as the set of its simplexes, each a sorted vertex list.
using Link = std::set<std::vector<VertexId>>;

// Adds the simplex with vertex set `vertices` and all its faces.
void add_closure(Link& link, std::vector<VertexId> vertices) {
  std::sort(vertices.begin(), vertices.end());
  const unsigned n = static_cast<unsigned>(vertices.size());
  for (unsigned subset = 1; subset < (1u << n); ++subset) {
    std::vector<VertexId> face;
    for (unsigned i = 0; i < n; ++i)
      if (subset & (1u << i)) face.push_back(vertices[i]);
    link.insert(std::move(face));
  }
}

// The vertices of s other than those of `center`.
std::vector<VertexId> without(const Simplex& s, const std::vector<VertexId>& center) {
  std::vector<VertexId> rest;
  for (VertexId v : s.vertices())
    if (std::find(center.begin(), center.end(), v) == center.end()) rest.push_back(v);
  return rest;
}

// Lk(center) in the mesh closed off by the virtual vertex; `elements` are those containing
// every vertex of `center`.
Link link_of(const Connectivity& c, const std::vector<ElementId>& elements, const std::vector<VertexId>& center) {
  Link link;
  for (ElementId e : elements) {
    const Element& element = c.element(e);
    add_closure(link, without(element.simplex, center));
    for (int j = 0; j <= c.dim(); ++j) {
      const Face& face = c.face(element.faces[j]);
      if (face.mate != no_id || !std::ranges::all_of(center, [&](VertexId v) { return face.simplex.contains(v); }))
        continue;
      std::vector<VertexId> cone = without(face.simplex, center);
      cone.push_back(virtual_vertex);
      add_closure(link, std::move(cone));
    }
  }
  return link;
}

std::string simplex_text(const std::vector<VertexId>& vertices) {
  std::string text = "{";
  for (std::size_t i = 0; i < vertices.size(); ++i)
    text += (i ? ", " : "") + (vertices[i] == virtual_vertex ? std::string("outside") : std::to_string(vertices[i]));
  return text + "}";
}

// A simplex in Lk(keep) ∩ Lk(gone) but not in Lk(keep gone), or none.
std::optional<std::vector<VertexId>> link_condition_violation(const Connectivity& c, VertexId keep, VertexId gone,
                                                              const std::vector<ElementId>& star_keep,
                                                              const std::vector<ElementId>& star_gone,
                                                              const std::vector<ElementId>& around) {
  const Link keep_link = link_of(c, star_keep, {keep});
  const Link gone_link = link_of(c, star_gone, {gone});
  const Link edge_link = link_of(c, around, {keep, gone});
  for (const std::vector<VertexId>& s : keep_link)
    if (gone_link.count(s) && !edge_link.count(s)) return s;
  return std::nullopt;
}

}  // namespace

EditResult collapse_edge(Mesh& mesh, VertexId keep, VertexId gone, double t) {
  // Part of a refusal message, built only when one is given.
  const auto edge = [&] { return "edge (" + std::to_string(keep) + ", " + std::to_string(gone) + ")"; };
  if (!(t >= 0 && t <= 1)) return EditResult::refused("collapse_edge: t = " + std::to_string(t) + " is not in [0, 1]");
  if (keep == gone || !mesh.is_vertex(keep) || !mesh.is_vertex(gone))
    return EditResult::refused("collapse_edge: " + edge() + " is not an edge of the mesh");
  const Connectivity& c = mesh.connectivity();
  const LocalStar star_keep = local_star(c, keep), star_gone = local_star(c, gone);
  std::vector<ElementId> around, survivors_gone, survivors_keep;
  for (ElementId e : star_gone.elements) (c.element(e).simplex.contains(keep) ? around : survivors_gone).push_back(e);
  if (around.empty()) return EditResult::refused("collapse_edge: " + edge() + " is not an edge of the mesh");
  for (ElementId e : star_keep.elements)
    if (!c.element(e).simplex.contains(gone)) survivors_keep.push_back(e);
  for (const auto& [v, star] : {std::pair{keep, &star_keep}, std::pair{gone, &star_gone}})
    if (!star->face_connected)
      return EditResult::refused("collapse_edge: vertex " + std::to_string(v) +
                                 " is pinched (its star is not face-connected)");
  // §3.2.3, Figure 3.10: the collapse must leave a manifold.
  if (auto s = link_condition_violation(c, keep, gone, star_keep.elements, star_gone.elements, around))
    return EditResult::refused("collapse_edge: " + edge() + " fails the link condition: " + simplex_text(*s) +
                               " is in the links of both vertices but not in the edge's, so the collapse would "
                               "make the mesh non-manifold");

  const VertexParents parents = VertexParents::on_edge(keep, gone, t);
  const std::vector<double> x = mesh.interpolated("collapse_edge", parents);  // exactly where move_vertex will put keep
  std::string why = spoiled_by_move(mesh, survivors_gone, gone, x);
  if (why.empty() && t != 0) why = spoiled_by_move(mesh, survivors_keep, keep, x);
  if (!why.empty()) return EditResult::refused("collapse_edge: collapsing " + edge() + ": " + why);

  ChangeBatch batch(mesh.connectivity());
  mesh.connectivity().replace_elements(around, {});
  std::vector<ElementSubstitution> substitution;
  substitution.reserve(survivors_gone.size());
  for (ElementId e : survivors_gone) substitution.push_back({e, {{gone, keep}}});
  mesh.connectivity().change_elements(substitution);
  if (t != 0) mesh.move_vertex(keep, parents);
  mesh.remove_vertex(gone);
  return EditResult::success();
}

}  // namespace snede
