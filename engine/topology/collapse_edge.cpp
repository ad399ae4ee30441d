#include "topology/collapse_edge.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "mesh/element_quality.hpp"
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

// The volume a tetrahedral mesh's star loses or gains when the collapse moves its corners — gone
// (and keep, when t ≠ 0) to x, the elements around the edge gone — with the round-off scale of
// that sum: Σ over the elements of Hadamard's bound ∏ |edge from corner 0| / d!, which bounds
// each determinant's terms. Moving an interior vertex inside its star, or a boundary vertex
// within a flat patch of boundary, conserves the measure exactly (the star's boundary stays
// where it was); a boundary vertex moved off its patch (a box's edge onto a cut's lip) does not.
struct MeasureChange {
  double change = 0, scale = 0;
};

MeasureChange measure_change(const Mesh& mesh, std::span<const ElementId> around,
                             std::span<const ElementId> survivors_gone, std::span<const ElementId> survivors_keep,
                             VertexId keep, VertexId gone, std::span<const double> x, bool keep_moves) {
  const int d = mesh.cell_dim(), space = mesh.space_dim();
  double factorial = 1;
  for (int k = 2; k <= d; ++k) factorial *= k;
  MeasureChange result;
  auto add = [&](ElementId e, VertexId moved, double sign) {
    std::vector<double> corners = mesh.corners(e);
    const auto oriented = mesh.connectivity().element(e).simplex.oriented_vertices();
    for (int i = 0; i <= d && moved != no_id; ++i)
      if (oriented[i] == moved) std::copy(x.begin(), x.end(), corners.begin() + i * space);
    result.change += sign * cell_measure(d, space, corners);
    double bound = 1 / factorial;
    for (int i = 1; i <= d; ++i) {
      double length2 = 0;
      for (int k = 0; k < space; ++k) length2 += std::pow(corners[i * space + k] - corners[k], 2);
      bound *= std::sqrt(length2);
    }
    result.scale += bound;
  };
  for (ElementId e : around) add(e, no_id, -1);
  for (ElementId e : survivors_gone) {
    add(e, no_id, -1);
    add(e, gone, +1);
  }
  for (ElementId e : survivors_keep) {
    if (!keep_moves) continue;
    add(e, no_id, -1);
    add(e, keep, +1);
  }
  return result;
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
  // A collapse must not reshape the body (issue 48 item 6: a cut's collapses moved boundary
  // vertices off their faces, and the cells overlapped, their volumes summing to 1.0000688 in
  // a unit box). 1e-13 of the round-off scale is ~450 ulps of the terms summed: far above the
  // rounding of a measure-conserving collapse, far below any real reshaping. Tetrahedral
  // meshes only: the 2D cutters contract short edges at a cut's exit on purpose (§5.3.2),
  // reshaping the boundary by less than ε_exit.
  if (mesh.cell_dim() == 3) {
    const MeasureChange m = measure_change(mesh, around, survivors_gone, survivors_keep, keep, gone, x, t != 0);
    if (!(std::abs(m.change) <= 1e-13 * m.scale))
      return EditResult::refused("collapse_edge: collapsing " + edge() + " would change the body's volume by " +
                                 std::to_string(m.change) +
                                 " (it moves a boundary vertex off its flat patch of boundary)");
  }
  // Nor invert a cell in the configuration a watcher's fields give it (a body's displacement:
  // gone's cells take keep's). A cell already refused before the collapse is not held against
  // it (the trial splits of degeneracy removal are undone by collapses, whatever the state).
  // With t ≠ 0 keep's own fields are interpolated anew, which the watchers cannot judge here.
  if (t == 0)
    for (ElementId e : survivors_gone) {
      const Simplex& before = c.element(e).simplex;
      if (std::string why = c.watcher_refusal(before.substituted(gone, keep)); !why.empty() && c.watcher_refusal(before).empty())
        return EditResult::refused("collapse_edge: collapsing " + edge() + ": element " + std::to_string(e) + " " + why);
    }

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
