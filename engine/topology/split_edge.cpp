#include "topology/split_edge.hpp"

#include <algorithm>

#include "topology/local_star.hpp"
#include "topology/orientation_checks.hpp"

namespace snede {

EditResult split_edge(Mesh& mesh, VertexId a, VertexId b, double t) {
  // Part of a refusal message, built only when one is given.
  const auto edge = [&] { return "edge (" + std::to_string(a) + ", " + std::to_string(b) + ")"; };
  if (!(t > 0 && t < 1)) return EditResult::refused("split_edge: t = " + std::to_string(t) + " is not in (0, 1)");
  if (a == b || !mesh.is_vertex(a) || !mesh.is_vertex(b))
    return EditResult::refused("split_edge: " + edge() + " is not an edge of the mesh");
  const Connectivity& c = mesh.connectivity();
  std::vector<ElementId> around = local_star(c, a).elements;
  std::erase_if(around, [&](ElementId e) { return !c.element(e).simplex.contains(b); });
  if (around.empty()) return EditResult::refused("split_edge: " + edge() + " is not an edge of the mesh");

  const VertexParents parents = VertexParents::on_edge(a, b, t);
  const std::vector<double> x = mesh.interpolated("split_edge", parents);
  // Each half is its element with one end of the edge moved to the new point.
  for (VertexId end : {a, b})
    if (std::string why = spoiled_by_move(mesh, around, end, x); !why.empty())
      return EditResult::refused("split_edge: splitting " + edge() + " at t = " + std::to_string(t) + ": " + why);

  const VertexId m = mesh.add_vertex(parents);  // before replace_elements, so watchers see it
  std::vector<Simplex> halves;
  halves.reserve(2 * around.size());
  for (ElementId e : around) {
    const Simplex& whole = c.element(e).simplex;
    // Substituting one end keeps the orientation.
    halves.push_back(whole.substituted(b, m));
    halves.push_back(whole.substituted(a, m));
  }
  mesh.connectivity().replace_elements(around, halves);
  return EditResult::success(m);
}

}  // namespace snede
