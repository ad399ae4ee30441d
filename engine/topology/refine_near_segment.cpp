#include "topology/refine_near_segment.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/segment_distance.hpp"
#include "mesh/element_quality.hpp"

namespace snede {
namespace {

// Whether the simplex with these reference corners comes within radius of the segment a–b
// (points of 2D meshes padded with z = 0): first its bounding ball (centroid, farthest
// corner), which rejects most of the tree cheaply, then the exact distance.
bool is_near(const Mesh& mesh, std::span<const VertexId> corners, const Point3& a, const Point3& b, double radius) {
  std::array<Point3, max_dimension + 1> points{};
  Point3 centre{};
  for (std::size_t i = 0; i < corners.size(); ++i)
    for (int k = 0; k < mesh.dim(); ++k) {
      points[i][k] = mesh.point(corners[i])[k];
      centre[k] += points[i][k] / static_cast<double>(corners.size());
    }
  double reach = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) reach = std::max(reach, distance(points[i], centre));
  if (segment_segment_distance(a, b, centre, centre) > radius + reach) return false;
  return segment_simplex_distance(a, b, std::span<const Point3>(points.data(), corners.size())) <= radius;
}

void check_point(std::span<const double> x, int dim, const char* name) {
  if (x.size() != static_cast<std::size_t>(dim))
    throw std::invalid_argument(std::string("refine_near_segment: ") + name + " has " + std::to_string(x.size()) +
                                " coordinates, the mesh is " + std::to_string(dim) + "-D");
  for (double c : x)
    if (!std::isfinite(c)) throw std::invalid_argument(std::string("refine_near_segment: ") + name + " is not finite");
}

}  // namespace

std::size_t refine_near_segment(Bisection& bisection, std::span<const double> a, std::span<const double> b, double h,
                                double radius, bool* near_found) {
  const Mesh& mesh = bisection.mesh();
  const int d = mesh.dim();
  if (!(std::isfinite(h) && h > 0))
    throw std::invalid_argument("refine_near_segment: h must be positive and finite, got " + std::to_string(h));
  if (!(std::isfinite(radius) && radius >= 0))
    throw std::invalid_argument("refine_near_segment: radius must be non-negative and finite, got " +
                                std::to_string(radius));
  check_point(a, d, "a");
  check_point(b, d, "b");
  Point3 from{}, to{};
  std::copy(a.begin(), a.end(), from.begin());
  std::copy(b.begin(), b.end(), to.begin());
  const RefinementHierarchy& tree = bisection.hierarchy();
  ChangeBatch batch(bisection.mesh().connectivity());  // one change for the watchers (§7.4)
  std::size_t n_split = 0;
  bool any_near = false;
  // Only roots whose boxes meet the segment's box grown by the radius can come within the
  // radius; they are searched in the order of all roots, so the splits come in the same order.
  BoundingBox reach_box;
  for (int k = 0; k < d; ++k) {
    reach_box.lo[k] = std::min(from[k], to[k]) - radius;
    reach_box.hi[k] = std::max(from[k], to[k]) + radius;
  }
  const std::vector<NodeId> near_roots = tree.roots_meeting(reach_box);
  std::vector<NodeId> stack;
  for (;;) {
    // The live elements near the segment with an edge longer than h, found by descending the
    // tree into the halves whose bounding balls come near it.
    std::vector<ElementId> too_long;
    stack = near_roots;
    while (!stack.empty()) {
      const RefinementNode& node = tree.node(stack.back());
      stack.pop_back();
      const std::span<const VertexId> corners(node.label.vertex.data(), static_cast<std::size_t>(d) + 1);
      if (!node.is_leaf()) {
        if (is_near(mesh, corners, from, to, radius)) stack.insert(stack.end(), node.children.begin(), node.children.end());
        continue;
      }
      if (node.element == no_id || !is_near(mesh, corners, from, to, radius)) continue;
      any_near = true;
      const double longest = longest_edge(d, mesh.corners(node.element));
      if (h < 1e-12 * longest) {
        std::ostringstream message;
        message << "refine_near_segment: h = " << h << " is below round-off for edges of " << longest;
        throw std::invalid_argument(message.str());
      }
      if (longest > h) too_long.push_back(node.element);
    }
    if (near_found) *near_found = any_near;
    if (!any_near && !near_found)
      throw std::invalid_argument("refine_near_segment: the segment does not come within radius " +
                                  std::to_string(radius) + " of the mesh");
    if (too_long.empty()) return n_split;
    // A split spreads to neighbours for conformity: an element listed here may be gone (its id
    // possibly reused by a new element elsewhere) by the time its turn comes; check it again.
    for (ElementId e : too_long) {
      if (!mesh.connectivity().is_element(e)) continue;
      const Simplex& simplex = mesh.connectivity().element(e).simplex;
      std::vector<VertexId> corners(static_cast<std::size_t>(d) + 1);
      for (int i = 0; i <= d; ++i) corners[i] = simplex.vertex(i);
      if (longest_edge(d, mesh.corners(e)) > h && is_near(mesh, corners, from, to, radius))
        n_split += bisection.bisect(e);
    }
  }
}

}  // namespace snede
