// §3.2.3 degeneracy removal: flat elements of each shape made by moving one interior vertex
// of a cube mesh, then removed. Checked against the mesh's own invariants (validate), the
// threshold, the class of the flattened element (computed independently here from where the
// vertex was put), and the total volume, which collapses of interior vertices keep exactly.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "topology/degeneracy_removal.hpp"
#include "topology/edit_checks.hpp"

namespace snede::testing {
namespace {

Eigen::Vector3d at(const Mesh& mesh, VertexId v) { return {mesh.point(v)[0], mesh.point(v)[1], mesh.point(v)[2]}; }

// Moves v to x if every element of its star stays positive; reports whether it did.
bool try_move(Mesh& mesh, VertexId v, const Eigen::Vector3d& x) {
  const std::vector<double> old(mesh.point(v).begin(), mesh.point(v).end());
  mesh.move_vertex(v, std::vector<double>{x[0], x[1], x[2]});
  for (ElementId e : local_star(mesh.connectivity(), v).elements)
    if (!(mesh.measure(e) > 0)) {
      mesh.move_vertex(v, old);
      return false;
    }
  return true;
}

// Interior vertices of the 4 × 4 × 4 Kuhn cube.
std::vector<VertexId> interior(const Mesh& mesh) {
  std::vector<VertexId> inside;
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (!on_boundary(mesh, v)) inside.push_back(v);
  return inside;
}

double min_aspect(const Mesh& mesh) {
  double worst = 1;
  for (const ElementQuality& q : mesh.quality()) worst = std::min(worst, q.aspect_ratio);
  return worst;
}

// Places an interior vertex so that one element of its star gets the wanted shape: `place`
// returns the target position for vertex v in element e with opposite face (a, b, c).
// With `shape` a cap, only where the vertex across the face is not joined to v: otherwise the
// collapse that removes the cap would duplicate that edge (Figure 3.10) and is refused.
template <class Place>
std::optional<DegenerateShape> flatten(Mesh& mesh, Place place, DegenerateShape shape, double large_angle) {
  const Connectivity& c = mesh.connectivity();
  for (VertexId v : interior(mesh))
    for (ElementId e : local_star(c, v).elements) {
      const Simplex face = c.element(e).simplex.subv(v);
      if (shape == DegenerateShape::cap) {
        const FaceId across = c.face(c.opposite_face(e, v)).mate;
        const VertexId m = c.opposite_vertex(c.face(across).element, across);
        const std::vector<VertexId> near = neighbours(mesh, v);
        if (std::find(near.begin(), near.end(), m) != near.end()) continue;
      }
      const Eigen::Vector3d a = at(mesh, face.vertex(0)), b = at(mesh, face.vertex(1)), c = at(mesh, face.vertex(2));
      if (try_move(mesh, v, place(at(mesh, v), a, b, c)))
        return degenerate_shape(mesh.corners(e), large_angle);
    }
  return std::nullopt;
}

struct Case {
  const char* name;
  DegenerateShape shape;
  // Target of the moved vertex from its position x and the opposite face (a, b, c).
  Eigen::Vector3d (*place)(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& c);
};

const Case cases[] = {
    // Next to a corner: a short edge, no large angle.
    {"needle", DegenerateShape::needle,
     [](const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d&, const Eigen::Vector3d&) {
       return Eigen::Vector3d(a + 2e-3 * (x - a));
     }},
    // Just above the middle of the opposite face: three large angles around it.
    {"cap", DegenerateShape::cap,
     [](const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
       const Eigen::Vector3d centre = (a + b + c) / 3;
       const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
       return Eigen::Vector3d(centre + 1e-4 * n * (n.dot(x - centre) > 0 ? 1 : -1));
     }},
    // Near the plane of (a, b, c) beyond edge (a, b): a convex quadrilateral, two large angles.
    {"sliver", DegenerateShape::sliver,
     [](const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
       const Eigen::Vector3d middle = 0.5 * (a + b);
       const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
       const Eigen::Vector3d inward = (c - middle).normalized();
       return Eigen::Vector3d(middle + 0.3 * (b - a).norm() * -inward + 1e-4 * n * (n.dot(x - middle) > 0 ? 1 : -1));
     }},
    // Just off the middle of edge (a, b): one large angle, at the edge from c to the vertex.
    {"spindle", DegenerateShape::spindle,
     [](const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
       const Eigen::Vector3d middle = 0.5 * (a + b);
       const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
       return Eigen::Vector3d(middle + 1e-3 * (c - middle) + 1e-4 * n * (n.dot(x - middle) > 0 ? 1 : -1));
     }},
};

TEST(DegeneracyRemoval, EachShapeIsRemovedAndTheVolumeKept) {
  const DegeneracyOptions options;
  for (const Case& shape_case : cases) {
    SCOPED_TRACE(shape_case.name);
    Mesh mesh = kuhn_cube(4);
    const double volume = total_measure(mesh);
    const std::optional<DegenerateShape> made = flatten(mesh, shape_case.place, shape_case.shape, options.large_angle);
    ASSERT_TRUE(made.has_value());
    EXPECT_EQ(static_cast<int>(*made), static_cast<int>(shape_case.shape));
    ASSERT_LT(min_aspect(mesh), options.min_aspect_ratio);
    std::vector<VertexId> everything;
    for (VertexId v = 0; v < mesh.n_points(); ++v) everything.push_back(v);
    const DegeneracyReport report = remove_degeneracies(mesh, everything, options);
    mesh.validate();
    EXPECT_GE(report.found, 1);
    EXPECT_GE(report.by_shape[static_cast<int>(*made)], 1);
    EXPECT_GE(min_aspect(mesh), options.min_aspect_ratio);
    EXPECT_GE(report.edges_collapsed, 1);
    // The spindle made here lies on an edge whose ring vertices it is joined to, so the
    // thesis's split-and-collapse fails the link condition and the flat pieces are cut free.
    if (*made != DegenerateShape::spindle) EXPECT_EQ(report.cut_free, 0);
    if (report.cut_free == 0) EXPECT_NEAR(total_measure(mesh), volume, 1e-12 * volume);
  }
}

TEST(DegeneracyRemoval, ClassifiesByTheNumberOfLargeDihedralAngles) {
  const double large = 0.99 * std::numbers::pi;
  // A regular-ish tetrahedron has none; a cap (apex just above the base's centroid) has three;
  // a sliver (four nearly coplanar points, a convex quadrilateral) two.
  const std::vector<double> good{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  EXPECT_EQ(degenerate_shape(good, large), DegenerateShape::needle);
  const std::vector<double> cap{0, 0, 0, 1, 0, 0, 0, 1, 0, 1.0 / 3, 1.0 / 3, 1e-5};
  EXPECT_EQ(degenerate_shape(cap, large), DegenerateShape::cap);
  const std::vector<double> sliver{0, 0, 0, 1, 1, 0, 1, 0, 1e-5, 0, 1, 1e-5};
  EXPECT_EQ(degenerate_shape(sliver, large), DegenerateShape::sliver);
}

TEST(DegeneracyRemoval, RefusesBadThresholdsAndTriangleMeshes) {
  Mesh mesh = kuhn_cube(2);
  DegeneracyOptions bad;
  bad.min_aspect_ratio = 0;
  EXPECT_THROW(remove_degeneracies(mesh, {}, bad), std::invalid_argument);
  bad = {};
  bad.large_angle = 4;
  EXPECT_THROW(remove_degeneracies(mesh, {}, bad), std::invalid_argument);
  Mesh square = right_triangle_square(2);
  EXPECT_THROW(remove_degeneracies(square, {}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace snede::testing
