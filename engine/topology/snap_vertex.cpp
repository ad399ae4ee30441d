#include "topology/snap_vertex.hpp"

#include "topology/local_star.hpp"
#include "topology/orientation_checks.hpp"

namespace snede {

EditResult snap_vertex(Mesh& mesh, VertexId v, const VertexParents& target) {
  if (!mesh.is_vertex(v) || mesh.connectivity().n_vertex_uses(v) == 0)
    return EditResult::refused("snap_vertex: vertex " + std::to_string(v) + " is not a vertex of any element");
  const std::vector<double> x = mesh.interpolated("snap_vertex", target);  // exactly where move_vertex will put v
  const std::vector<ElementId> star = local_star(mesh.connectivity(), v).elements;
  if (std::string why = spoiled_by_move(mesh, star, v, x); !why.empty())
    return EditResult::refused("snap_vertex: " + why);
  mesh.move_vertex(v, target);
  return EditResult::success();
}

}  // namespace snede
