// The tetrahedral cutter (§3.2–§3.3) on a bare mesh and on a body given by its displacement and
// supports alone (no Model): a planar cut through a box makes two pieces (our own flood fill)
// of the box's volume, every cell positive and the mesh valid; a cut of a rigidly translated
// body equals the cut of the translated mesh; supports are not snapped; the free-piece calls
// are made after a separation only, with a face of each free piece.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <vector>

#include "cutter_checks.hpp"
#include "cutting/tetrahedral_cutter.hpp"

namespace snede::testing {
namespace {

using Scalpel = std::array<double, 6>;

// Scalpel positions sweeping the whole unit box through the plane n·x = offset: a blade of
// length 6 in the plane, moved along the plane from one side of the box to the other.
std::vector<Scalpel> planar_path(Point3 n, double offset, int steps) {
  n = plus_scaled({0, 0, 0}, 1 / norm(n), n);
  const Point3 helper = std::abs(n[2]) < 0.9 ? Point3{0, 0, 1} : Point3{1, 0, 0};
  Point3 blade = cross(n, helper);
  blade = plus_scaled({0, 0, 0}, 1 / norm(blade), blade);
  const Point3 travel = cross(n, blade);
  const Point3 centre{0.5, 0.5, 0.5};
  const Point3 base = plus_scaled(centre, offset - dot(n, centre), n);
  std::vector<Scalpel> path;
  for (int i = 0; i < steps; ++i) {
    const Point3 middle = plus_scaled(base, -2.0 + 4.0 * i / (steps - 1), travel);
    const Point3 a = plus_scaled(middle, -3, blade), b = plus_scaled(middle, 3, blade);
    path.push_back({a[0], a[1], a[2], b[0], b[1], b[2]});
  }
  return path;
}

Scalpel shifted(Scalpel s, const std::vector<double>& t) {
  for (int k = 0; k < 6; ++k) s[k] += t[k % 3];
  return s;
}

CutResult cut_along(TetrahedralCutter& cutter, const std::vector<Scalpel>& path) {
  CutResult total;
  for (const Scalpel& s : path) total.add(cutter.move(s));
  return total;
}

CutterOptions without_degeneracy_removal() {
  CutterOptions options;
  options.remove_degeneracies = false;
  return options;
}

TEST(TetrahedralCutter, APlaneThroughTheBoxMakesTwoPiecesOfTheBoxsVolume) {
  for (const bool remove : {false, true}) {
    Mesh mesh = kuhn_cube(6);
    const double volume = total_measure(mesh);
    ASSERT_NEAR(volume, 1.0, 1e-12);
    CutterOptions options;
    options.remove_degeneracies = remove;
    TetrahedralCutter cutter(mesh, CutBody{}, options);
    const CutResult report = cut_along(cutter, planar_path({1, 0.4, 0.2}, 0.55, 3));
    EXPECT_EQ(count_pieces(mesh), 2) << "degeneracy removal " << remove;
    EXPECT_EQ(report.components, 2);
    EXPECT_GT(report.faces_dissected, 36);  // at least the 6 × 6 × 2 faces of a grid plane
    expect_sound(mesh);
    // Snapping within the box and on its flat faces keeps its shape; removals by collapse may
    // move a vertex on the box's faces only.
    EXPECT_NEAR(total_measure(mesh), volume, 1e-12) << "degeneracy removal " << remove;
  }
}

TEST(TetrahedralCutter, ACutThatStopsInsideLeavesOnePiece) {
  Mesh mesh = kuhn_cube(8);
  TetrahedralCutter cutter(mesh, CutBody{}, CutterOptions{});
  const CutResult report = cut_along(cutter, {{0.43, -0.5, -1, 0.43, -0.5, 2}, {0.43, 0.2, -1, 0.43, 0.2, 2},
                                              {0.43, 0.6, -1, 0.43, 0.6, 2}});
  EXPECT_GT(report.faces_dissected, 0);
  EXPECT_EQ(count_pieces(mesh), 1);
  expect_sound(mesh);
}

TEST(TetrahedralCutter, ACutOfARigidlyTranslatedBodyIsTheCutOfTheTranslatedMesh) {
  const std::vector<double> t{0.25, -0.5, 1.0};  // exact sums with the grid's coordinates
  Mesh displaced = kuhn_cube(4);
  Mesh moved = translated(displaced, t);
  std::vector<Scalpel> path = planar_path({1, 0.3, -0.2}, 0.4, 4);
  for (Scalpel& s : path) s = shifted(s, t);
  TetrahedralCutter on_body(displaced, CutBody{rigid_displacement(displaced, t), {}, {}, {}}, CutterOptions{});
  TetrahedralCutter on_mesh(moved, CutBody{}, CutterOptions{});
  const CutResult body_report = cut_along(on_body, path);
  const CutResult mesh_report = cut_along(on_mesh, path);
  EXPECT_EQ(body_report.faces_dissected, mesh_report.faces_dissected);
  EXPECT_EQ(body_report.vertices_snapped, mesh_report.vertices_snapped);
  EXPECT_GT(body_report.vertices_snapped, 0);
  EXPECT_EQ(count_pieces(displaced), 2);
  expect_same_cut_translated(displaced, t, moved, 1e-12);
}

// The vertices of a 4³ box on the grid plane x = 0.5, which a cut along x = 0.52 snaps.
std::set<VertexId> on_plane_x_half(const Mesh& mesh) {
  std::set<VertexId> on;
  for (VertexId v = 0; v < mesh.n_points(); ++v)
    if (mesh.point(v)[0] == 0.5) on.insert(v);
  return on;
}

TEST(TetrahedralCutter, SupportsStayWhereTheyAre) {
  for (const bool supported : {false, true}) {
    Mesh mesh = kuhn_cube(4);
    const std::set<VertexId> supports = on_plane_x_half(mesh);
    CutBody body;
    if (supported) body.is_support = [&](VertexId v) { return supports.count(v) > 0; };
    TetrahedralCutter cutter(mesh, body, without_degeneracy_removal());
    const CutResult report = cut_along(cutter, planar_path({1, 0, 0}, 0.52, 3));
    int left_in_place = 0;
    for (VertexId v : supports) left_in_place += mesh.point(v)[0] == 0.5;
    if (supported) {
      EXPECT_EQ(left_in_place, static_cast<int>(supports.size()));
      EXPECT_GT(report.snaps_refused, 0);
    } else {
      EXPECT_LT(left_in_place, static_cast<int>(supports.size()));  // snapped onto x = 0.52
    }
    expect_sound(mesh);
  }
}

// A body held at x = 0: the pieces with none of those vertices are free (by our flood fill).
struct HeldAtTheLeft {
  const Mesh& mesh;
  int queries = 0;
  std::vector<std::vector<VertexId>> held_faces;

  bool support(VertexId v) const { return mesh.point(v)[0] == 0; }
  std::vector<ElementId> free_pieces() {
    ++queries;
    const std::vector<int> piece = piece_of_each_cell(mesh);
    const std::vector<std::vector<VertexId>> rows = cell_rows(mesh);
    const std::vector<ElementId> ids = mesh.cell_ids();
    std::set<int> held;
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (VertexId v : rows[r])
        if (support(v)) held.insert(piece[r]);
    std::vector<ElementId> cells;
    std::set<int> listed;
    for (std::size_t r = 0; r < rows.size(); ++r)
      if (!held.count(piece[r]) && listed.insert(piece[r]).second) cells.push_back(ids[r]);
    return cells;
  }
  CutBody body() {
    return {{},
            [this](VertexId v) { return support(v); },
            [this] { return free_pieces(); },
            [this](std::span<const VertexId> face) { held_faces.emplace_back(face.begin(), face.end()); }};
  }
};

TEST(TetrahedralCutter, APieceCutFreeOfTheSupportsIsHeldOnOneOfItsFaces) {
  Mesh mesh = kuhn_cube(4);
  HeldAtTheLeft left{mesh};
  TetrahedralCutter cutter(mesh, left.body(), CutterOptions{});
  // A cut that separates nothing asks nothing.
  cut_along(cutter, {{0.6, -0.5, -1, 0.6, -0.5, 2}, {0.6, 0.3, -1, 0.6, 0.3, 2}});
  EXPECT_EQ(left.queries, 0);
  cutter.lift();
  const CutResult report = cut_along(cutter, planar_path({1, 0.1, 0.05}, 0.6, 3));
  ASSERT_EQ(count_pieces(mesh), 2);
  EXPECT_GE(left.queries, 1);
  EXPECT_EQ(report.free_pieces, 1);
  EXPECT_EQ(report.pieces_fixed, 1);
  ASSERT_EQ(left.held_faces.size(), 1u);
  // The face is a face of a cell of the piece without supports.
  const std::vector<VertexId>& face = left.held_faces[0];
  ASSERT_EQ(face.size(), 3u);
  const std::vector<int> piece = piece_of_each_cell(mesh);
  const std::vector<std::vector<VertexId>> rows = cell_rows(mesh);
  const auto holds = [&](const std::vector<VertexId>& cell) {
    return std::all_of(face.begin(), face.end(), [&](VertexId v) { return std::count(cell.begin(), cell.end(), v) > 0; });
  };
  std::set<int> supported;
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (VertexId v : rows[r])
      if (left.support(v)) supported.insert(piece[r]);
  int cells_with_face = 0;
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (holds(rows[r])) {
      ++cells_with_face;
      EXPECT_FALSE(supported.count(piece[r]));
    }
  EXPECT_GE(cells_with_face, 1);
  expect_sound(mesh);
}

TEST(TetrahedralCutter, FreePiecesAreOnlyCountedWhenHoldingThemIsOff) {
  Mesh mesh = kuhn_cube(4);
  HeldAtTheLeft left{mesh};
  CutterOptions options;
  options.fix_free_pieces = false;
  TetrahedralCutter cutter(mesh, left.body(), options);
  const CutResult report = cut_along(cutter, planar_path({1, 0.1, 0.05}, 0.6, 3));
  EXPECT_EQ(report.free_pieces, 1);
  EXPECT_EQ(report.pieces_fixed, 0);
  EXPECT_TRUE(left.held_faces.empty());
}

// The mesh without its removed vertices, live vertices and cells kept in order (as a distributed
// body's cutting rank rebuilds its part); new_of_old maps the vertex ids (−1: removed).
Mesh compacted(const Mesh& mesh, std::vector<VertexId>& new_of_old) {
  new_of_old.assign(static_cast<std::size_t>(mesh.n_points()), -1);
  std::vector<double> points;
  for (VertexId v = 0, next = 0; v < mesh.n_points(); ++v)
    if (mesh.is_vertex(v)) {
      new_of_old[static_cast<std::size_t>(v)] = next++;
      points.insert(points.end(), mesh.point(v).begin(), mesh.point(v).end());
    }
  std::vector<std::int64_t> cells;
  for (VertexId v : mesh.cells()) cells.push_back(new_of_old[static_cast<std::size_t>(v)]);
  return Mesh(3, 3, std::move(points), cells);
}

// Each cell as its corners' coordinates, sorted; the list sorted: a mesh's cells whatever the
// numbering.
std::vector<std::vector<double>> cell_coordinates(const Mesh& mesh) {
  std::vector<std::vector<double>> all;
  for (const std::vector<VertexId>& row : cell_rows(mesh)) {
    std::vector<std::array<double, 3>> corners;
    for (VertexId v : row) corners.push_back({mesh.point(v)[0], mesh.point(v)[1], mesh.point(v)[2]});
    std::sort(corners.begin(), corners.end());
    std::vector<double> flat;
    for (const auto& x : corners) flat.insert(flat.end(), x.begin(), x.end());
    all.push_back(flat);
  }
  std::sort(all.begin(), all.end());
  return all;
}

TEST(TetrahedralCutter, ACutterGoesOnFromItsMemoryInACompactedCopyOfItsMesh) {
  // Half a path cut, then the rest twice: by the same cutter, and by a new one on a copy of the
  // mesh without its removed vertices (its faces and elements numbered anew), restored from the
  // first one's memory mapped to the copy.
  // The memory matters: the first half leaves tetrahedra incomplete (the blade stops inside)
  // and an incision whose faces the second half extends.
  const std::vector<Scalpel> path = planar_path({1, 0.35, 0.15}, 0.47, 33);
  Mesh mesh = kuhn_cube(6);
  TetrahedralCutter cutter(mesh, CutBody{}, CutterOptions{});
  cut_along(cutter, {path.begin(), path.begin() + 16});
  const CutterMemory memory = cutter.memory();
  ASSERT_TRUE(memory.scalpel.has_value());
  ASSERT_FALSE(memory.incision.empty());
  ASSERT_FALSE(memory.previous_touched.empty());

  std::vector<VertexId> new_of_old;
  Mesh copy = compacted(mesh, new_of_old);
  const auto map = [&](VertexId v) { return new_of_old[static_cast<std::size_t>(v)]; };
  CutterMemory mapped = memory;
  for (VertexId& v : mapped.placed) v = map(v);
  for (auto* simplexes : {&mapped.joined, &mapped.incision, &mapped.previous_touched})
    for (Simplex& sigma : *simplexes) sigma = sigma.mapped(map);
  TetrahedralCutter going_on(copy, CutBody{}, CutterOptions{});
  going_on.restore(mapped);

  const CutResult straight = cut_along(cutter, {path.begin() + 16, path.end()});
  const CutResult restored = cut_along(going_on, {path.begin() + 16, path.end()});
  EXPECT_GT(straight.faces_dissected, 0);
  EXPECT_EQ(restored.faces_dissected, straight.faces_dissected);
  EXPECT_EQ(restored.vertices_snapped, straight.vertices_snapped);
  EXPECT_EQ(count_pieces(copy), count_pieces(mesh));
  EXPECT_EQ(count_pieces(mesh), 2);
  EXPECT_EQ(cell_coordinates(copy), cell_coordinates(mesh));
  EXPECT_EQ(going_on.incision_faces().size(), cutter.incision_faces().size());
  expect_sound(copy);
}

TEST(TetrahedralCutter, RestoreRefusesAFaceTheMeshDoesNotHave) {
  Mesh mesh = kuhn_cube(2);
  TetrahedralCutter cutter(mesh, CutBody{}, CutterOptions{});
  CutterMemory memory;
  memory.incision.push_back(Simplex(1, {0, 1, 26}));
  EXPECT_THROW(cutter.restore(memory), std::invalid_argument);
  memory.incision.clear();
  memory.placed.push_back(mesh.n_points());
  EXPECT_THROW(cutter.restore(memory), std::invalid_argument);
  memory.placed.clear();
  memory.cut_configuration.assign(5, 0.0);
  EXPECT_THROW(cutter.restore(memory), std::invalid_argument);
}

}  // namespace
}  // namespace snede::testing
