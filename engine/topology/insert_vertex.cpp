#include "topology/insert_vertex.hpp"

#include <cmath>
#include <stdexcept>

#include "core/predicates.hpp"
#include "topology/triangle_checks.hpp"

namespace snede {

namespace {

void check_weights(std::span<const double> weights, std::size_t n_corners) {
  if (weights.size() != n_corners)
    throw std::invalid_argument("insert_vertex: " + std::to_string(weights.size()) + " weights for an element of " +
                                std::to_string(n_corners) + " corners");
  double sum = 0;
  for (double w : weights) {
    if (!std::isfinite(w) || w < 0)
      throw std::invalid_argument("insert_vertex: weight " + std::to_string(w) +
                                  " is not a barycentric coordinate (each must be finite and ≥ 0)");
    sum += w;
  }
  if (std::abs(sum - 1) > 1e-12)
    throw std::invalid_argument("insert_vertex: weights sum to " + std::to_string(sum) + ", not 1");
}

// True if `cell` with corner `replaced` moved to `position` is positively oriented, exactly
// (on a surface: not degenerate; the position lies in the cell's plane up to rounding).
bool positive_with_corner_at(const Mesh& mesh, const Simplex& cell, VertexId replaced, const double* position) {
  const auto oriented = cell.oriented_vertices();
  std::array<const double*, 4> x{};
  for (int i = 0; i < cell.count(); ++i) x[i] = oriented[i] == replaced ? position : mesh.point(oriented[i]).data();
  if (mesh.is_surface()) return !collinear_3d(x[0], x[1], x[2]);
  if (mesh.cell_dim() == 2) return orientation_2d(x[0], x[1], x[2]) > 0;
  return orientation_3d(x[0], x[1], x[2], x[3]) > 0;
}

}  // namespace

EditResult insert_vertex(Mesh& mesh, ElementId e, std::span<const double> weights) {
  Connectivity& c = mesh.connectivity();
  if (!c.is_element(e)) throw std::invalid_argument("insert_vertex: element " + std::to_string(e) + " does not exist");
  const Simplex& cell = c.element(e).simplex;
  const int n_corners = cell.count();
  check_weights(weights, n_corners);
  const auto corners = cell.oriented_vertices();
  VertexParents parents;
  std::vector<VertexId> zero_weight;
  for (int i = 0; i < n_corners; ++i) {
    if (weights[i] > 0) {
      parents.vertex.push_back(corners[i]);
      parents.weight.push_back(weights[i]);
    } else {
      zero_weight.push_back(corners[i]);
    }
  }
  // Part of a refusal message, built only when one is given.
  const auto where = [&] { return "insert_vertex in element " + std::to_string(e) + ": "; };
  if (parents.count() == 1)
    return EditResult::refused(where() + "the point is vertex " + std::to_string(parents.vertex[0]) + ", nothing to insert");
  if (parents.count() == 2)
    return EditResult::refused(where() + "the point lies on edge " + vertex_list({parents.vertex[0], parents.vertex[1]}) +
                               " (the other weights are 0): use split_edge");

  // The cells to split and, per cell, the corners the new vertex takes the place of: all of
  // e's, or those of the face the point lies on in e and in its neighbour across that face.
  std::vector<ElementId> split{e};
  if (!zero_weight.empty()) {
    const FaceId face = c.opposite_face(e, zero_weight[0]);
    if (c.face(face).mate != no_id) split.push_back(c.face(c.face(face).mate).element);
  }
  const std::vector<double> position = mesh.interpolated("insert_vertex", parents);
  for (ElementId cell_id : split)
    for (VertexId corner : parents.vertex)
      if (!positive_with_corner_at(mesh, c.element(cell_id).simplex, corner, position.data()))
        return EditResult::refused(where() + "the point is too close to the side of element " + std::to_string(cell_id) +
                                   " opposite vertex " + std::to_string(corner) +
                                   ": the new cell would be degenerate or inverted (exact orientation)");

  const VertexId vertex = mesh.add_vertex(parents);  // before replace_elements: watchers see it with the change
  std::vector<Simplex> pieces;
  for (ElementId cell_id : split)
    for (VertexId corner : parents.vertex) pieces.push_back(c.element(cell_id).simplex.substituted(corner, vertex));
  c.replace_elements(split, pieces);
  return EditResult::success(vertex);
}

}  // namespace snede
