#include "mesh/mesh.hpp"

#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "mesh/traversal.hpp"
#include "mesh/validate.hpp"

namespace snede {
namespace {

std::vector<double> gather_corners(int space_dim, const std::vector<double>& points, std::span<const VertexId> cell) {
  std::vector<double> corners;
  corners.reserve(cell.size() * space_dim);
  for (VertexId v : cell)
    for (int k = 0; k < space_dim; ++k) corners.push_back(points[static_cast<std::size_t>(v) * space_dim + k]);
  return corners;
}

std::vector<VertexId> checked_cells(int cell_dim, int space_dim, const std::vector<double>& points,
                                    std::span<const std::int64_t> given, std::size_t& n_reoriented) {
  const int nv = cell_dim + 1;
  const auto n_points = static_cast<std::int64_t>(points.size() / space_dim);
  std::vector<VertexId> cells(given.size());
  for (std::size_t c = 0; c < cells.size() / nv; ++c) {
    std::span<VertexId> cell(cells.data() + c * nv, nv);
    for (int i = 0; i < nv; ++i) {
      const std::int64_t v = given[c * nv + i];
      if (v < 0 || v >= n_points)
        throw std::invalid_argument("cell " + std::to_string(c) + " refers to vertex " + std::to_string(v) +
                                    ", but vertex ids must be in 0.." + std::to_string(n_points - 1));
      cell[i] = static_cast<VertexId>(v);
      for (int j = 0; j < i; ++j)
        if (cell[i] == cell[j])
          throw std::invalid_argument("cell " + std::to_string(c) + " repeats vertex " + std::to_string(cell[i]));
    }
    const std::vector<double> corners = gather_corners(space_dim, points, cell);
    const double volume = cell_measure(cell_dim, space_dim, corners);
    if (has_zero_volume(cell_dim, space_dim, corners)) {
      std::ostringstream message;
      message << "cell " << c << " has zero " << (cell_dim == 2 ? "area" : "volume") << " (" << volume
              << " for a longest edge of " << cell_longest_edge(cell_dim, space_dim, corners) << ")";
      throw std::invalid_argument(message.str());
    }
    // The predicate above is exact at any scale, but the finite elements compute with the
    // measure itself: one that underflows (to 0 or a subnormal) or overflows would make the
    // body's kernels divide by zero or give inf, so such a mesh is refused here, not later.
    if (!std::isnormal(volume)) {
      std::ostringstream message;
      const bool too_small = std::abs(volume) < std::numeric_limits<double>::min();
      message << "cell " << c << "'s " << (cell_dim == 2 ? "area" : "volume") << " is "
              << (too_small ? "too small" : "too large") << " for double precision (" << volume
              << " for corners " << corner_extent(space_dim, corners) << " apart): express the "
              << "coordinates in " << (too_small ? "smaller" : "larger") << " units";
      throw std::invalid_argument(message.str());
    }
    if (volume < 0) {
      std::swap(cell[0], cell[1]);
      ++n_reoriented;
    }
  }
  return cells;
}

// Orients the triangles of a surface consistently (neighbours traverse their shared edge in
// opposite directions), by a walk over each connected component from its first triangle.
// Edges shared by more than two triangles are left for from_cells to refuse.
void orient_surface(std::span<VertexId> cells, std::size_t& n_reoriented) {
  const std::size_t n = cells.size() / 3;
  struct Use {
    std::size_t cell;
    bool forward;  // the cell runs along the edge from its smaller to its larger vertex
  };
  std::unordered_map<std::uint64_t, std::vector<Use>> edges;
  auto key = [](VertexId a, VertexId b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  auto for_each_edge = [&](std::size_t c, auto&& visit) {
    for (int i = 0; i < 3; ++i) {
      const VertexId a = cells[3 * c + i], b = cells[3 * c + (i + 1) % 3];
      visit(key(a, b), a < b);
    }
  };
  for (std::size_t c = 0; c < n; ++c)
    for_each_edge(c, [&](std::uint64_t k, bool forward) { edges[k].push_back({c, forward}); });
  std::vector<std::int8_t> flipped(n, -1);  // -1: not reached yet
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (flipped[seed] >= 0) continue;
    flipped[seed] = 0;
    std::vector<std::size_t> stack{seed};
    while (!stack.empty()) {
      const std::size_t c = stack.back();
      stack.pop_back();
      for_each_edge(c, [&](std::uint64_t k, bool forward) {
        const auto& uses = edges[k];
        if (uses.size() != 2) return;
        const Use other = uses[0].cell == c ? uses[1] : uses[0];
        // Consistent when the two run the edge in opposite directions after their flips.
        const bool other_flip = (forward ^ static_cast<bool>(flipped[c])) == other.forward;
        if (flipped[other.cell] < 0) {
          flipped[other.cell] = other_flip;
          stack.push_back(other.cell);
        } else if (static_cast<bool>(flipped[other.cell]) != other_flip) {
          throw std::invalid_argument("the surface is not orientable: triangles " + std::to_string(c) + " and " +
                                      std::to_string(other.cell) + " cannot be oriented consistently");
        }
      });
    }
  }
  for (std::size_t c = 0; c < n; ++c)
    if (flipped[c] > 0) {
      std::swap(cells[3 * c], cells[3 * c + 1]);
      ++n_reoriented;
    }
}

}  // namespace

Mesh::Mesh(int cell_dim, int space_dim, std::vector<double> points, std::span<const std::int64_t> cells)
    : space_dim_(space_dim), points_(std::move(points)), connectivity_(cell_dim == 3 ? 3 : 2) {
  if (!((cell_dim == 2 && (space_dim == 2 || space_dim == 3)) || (cell_dim == 3 && space_dim == 3)))
    throw std::invalid_argument("a mesh has triangles in 2D or 3D or tetrahedra in 3D; got cells of dimension " +
                                std::to_string(cell_dim) + " in " + std::to_string(space_dim) + "-D space");
  if (points_.size() % space_dim != 0 || cells.size() % (cell_dim + 1) != 0)
    throw std::invalid_argument("points must be (n, " + std::to_string(space_dim) + ") and cells (m, " +
                                std::to_string(cell_dim + 1) + ")");
  if (points_.size() / space_dim > static_cast<std::size_t>(std::numeric_limits<VertexId>::max()))
    throw std::invalid_argument("too many points for 32-bit vertex ids");
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (!std::isfinite(points_[i])) {
      std::ostringstream message;
      message << "point " << i / space_dim << " has a non-finite coordinate (" << points_[i] << ")";
      throw std::invalid_argument(message.str());
    }
  std::vector<VertexId> oriented = checked_cells(cell_dim, space_dim, points_, cells, n_reoriented_);
  if (cell_dim < space_dim) orient_surface(oriented, n_reoriented_);
  connectivity_ = Connectivity::from_cells(cell_dim, oriented);
  alive_.assign(n_points(), 1);
}

std::vector<VertexId> Mesh::cells() const {
  const int nv = cell_dim() + 1;
  std::vector<VertexId> cells;
  cells.reserve(n_cells() * nv);
  for (ElementId e : connectivity_.element_ids()) {
    const auto oriented = connectivity_.element(e).simplex.oriented_vertices();
    cells.insert(cells.end(), oriented.begin(), oriented.begin() + nv);
  }
  return cells;
}

std::vector<ElementId> Mesh::cell_ids() const { return connectivity_.element_ids(); }

std::vector<double> Mesh::corners(ElementId e) const {
  const auto oriented = connectivity_.element(e).simplex.oriented_vertices();
  return gather_corners(space_dim_, points_, std::span<const VertexId>(oriented.data(), cell_dim() + 1));
}

double Mesh::measure(ElementId e) const { return cell_measure(cell_dim(), space_dim_, corners(e)); }

std::vector<ElementQuality> Mesh::quality() const {
  std::vector<ElementQuality> q;
  q.reserve(n_cells());
  for (ElementId e : connectivity_.element_ids()) {
    const std::vector<double> x = corners(e);
    q.push_back(is_surface() ? element_quality(2, flattened_triangle(x)) : element_quality(cell_dim(), x));
  }
  return q;
}

std::vector<VertexId> Mesh::boundary_faces() const {
  std::vector<VertexId> faces;
  for (FaceId f : snede::boundary_faces(connectivity_)) {
    const auto oriented = connectivity_.face(f).simplex.oriented_vertices();
    faces.insert(faces.end(), oriented.begin(), oriented.begin() + cell_dim());
  }
  return faces;
}

std::vector<FaceId> Mesh::find_faces(const std::vector<VertexId>& face_vertices) const {
  const int nv = cell_dim();
  if (face_vertices.size() % nv != 0)
    throw std::invalid_argument("faces must be (n, " + std::to_string(nv) + ") vertex ids");
  // Keyed by the vertex set (positive orientation), so a boundary face of either sign is found.
  auto unsigned_key = [](const Simplex& s) { return s.sign() > 0 ? s : s.mate(); };
  std::unordered_map<Simplex, FaceId, SimplexHash> wanted;
  for (std::size_t i = 0; i < face_vertices.size() / nv; ++i)
    wanted.emplace(unsigned_key(Simplex(1, std::span<const VertexId>(face_vertices.data() + i * nv, nv))), no_id);
  for (FaceId f = 0; f < connectivity_.face_capacity(); ++f) {
    if (!connectivity_.is_face(f)) continue;
    if (auto it = wanted.find(unsigned_key(connectivity_.face(f).simplex)); it != wanted.end() && it->second == no_id)
      it->second = f;
  }
  std::vector<FaceId> found;
  for (const auto& [s, f] : wanted) {
    if (f == no_id) throw std::invalid_argument("no face with vertices " + s.to_string().substr(1) + " in the mesh");
    found.push_back(f);
  }
  return found;
}

void Mesh::check_live_vertex(const char* operation, VertexId v) const {
  if (!is_vertex(v))
    throw std::invalid_argument(std::string(operation) + ": vertex " + std::to_string(v) +
                                (v >= 0 && v < n_points() ? " was removed" : " does not exist"));
}

std::vector<double> Mesh::interpolated(const char* operation, const VertexParents& parents) const {
  if (parents.count() == 0 || parents.weight.size() != parents.count())
    throw std::invalid_argument(std::string(operation) + ": needs at least one parent and one weight per parent");
  double sum = 0;
  for (std::size_t i = 0; i < parents.count(); ++i) {
    check_live_vertex(operation, parents.vertex[i]);
    if (!std::isfinite(parents.weight[i]))
      throw std::invalid_argument(std::string(operation) + ": weight " + std::to_string(parents.weight[i]) +
                                  " of parent " + std::to_string(parents.vertex[i]) + " is not finite");
    sum += parents.weight[i];
  }
  if (std::abs(sum - 1) > 1e-12)
    throw std::invalid_argument(std::string(operation) + ": parent weights sum to " + std::to_string(sum) +
                                ", not 1 (they are barycentric coordinates)");
  std::vector<double> x(space_dim_, 0.0);
  for (std::size_t i = 0; i < parents.count(); ++i)
    for (int k = 0; k < space_dim_; ++k) x[k] += parents.weight[i] * point(parents.vertex[i])[k];
  return x;
}

VertexId Mesh::add_vertex(const VertexParents& parents) {
  const std::vector<double> x = interpolated("add_vertex", parents);
  VertexId v;
  if (!free_vertices_.empty()) {
    v = free_vertices_.back();
    free_vertices_.pop_back();
    std::copy(x.begin(), x.end(), points_.begin() + static_cast<std::ptrdiff_t>(v) * space_dim_);
    alive_[v] = 1;
  } else {
    if (n_points() == std::numeric_limits<VertexId>::max()) throw std::length_error("add_vertex: 32-bit vertex ids exhausted");
    v = n_points();
    points_.insert(points_.end(), x.begin(), x.end());
    alive_.push_back(1);
  }
  parents_[v] = parents;
  connectivity_.stage_vertex_event({VertexEventKind::added, v, parents});
  return v;
}

VertexParents Mesh::parents(VertexId v) const {
  const auto it = parents_.find(v);
  return it == parents_.end() ? VertexParents{} : it->second;
}

void Mesh::move_vertex(VertexId v, const VertexParents& parents) {
  check_live_vertex("move_vertex", v);
  const std::vector<double> x = interpolated("move_vertex", parents);
  std::copy(x.begin(), x.end(), points_.begin() + static_cast<std::ptrdiff_t>(v) * space_dim_);
  connectivity_.stage_vertex_event({VertexEventKind::moved, v, parents});
  connectivity_.notify_vertex_events();
}

void Mesh::move_vertex(VertexId v, std::span<const double> x) {
  check_live_vertex("move_vertex", v);
  if (x.size() != static_cast<std::size_t>(space_dim_))
    throw std::invalid_argument("move_vertex: the point has " + std::to_string(x.size()) + " coordinates, the mesh " +
                                std::to_string(space_dim_));
  for (double xk : x)
    if (!std::isfinite(xk)) throw std::invalid_argument("move_vertex: non-finite coordinate for vertex " + std::to_string(v));
  std::copy(x.begin(), x.end(), points_.begin() + static_cast<std::ptrdiff_t>(v) * space_dim_);
  connectivity_.stage_vertex_event({VertexEventKind::moved, v, {}});
  connectivity_.notify_vertex_events();
}

void Mesh::remove_vertex(VertexId v) {
  check_live_vertex("remove_vertex", v);
  if (const int uses = connectivity_.n_vertex_uses(v); uses > 0)
    throw std::invalid_argument("remove_vertex: vertex " + std::to_string(v) + " is still used by " +
                                std::to_string(uses) + " cell(s)");
  alive_[v] = 0;
  free_vertices_.push_back(v);
  parents_.erase(v);
  connectivity_.stage_vertex_event({VertexEventKind::removed, v, {}});
  connectivity_.notify_vertex_events();
}

void Mesh::validate() const {
  if (auto violation = find_violation(connectivity_)) throw InvalidMesh(*violation);
  for (ElementId e : connectivity_.element_ids()) {
    const Simplex& s = connectivity_.element(e).simplex;
    for (VertexId v : s.vertices())
      if (!is_vertex(v))
        throw InvalidMesh("element " + std::to_string(e) + " " + s.to_string() + " uses vertex " + std::to_string(v) +
                          (v < n_points() ? ", which was removed" : " beyond the " + std::to_string(n_points()) + " points"));
    if (!(measure(e) > 0))
      throw InvalidMesh("element " + std::to_string(e) + " " + s.to_string() +
                        (is_surface() ? " has zero area" : " is not positively oriented"));
    // The test construction applies: a cell flat to rounding is not valid either.
    if (has_zero_volume(cell_dim(), space_dim_, corners(e)))
      throw InvalidMesh("element " + std::to_string(e) + " " + s.to_string() + " is flat to rounding (" +
                        (cell_dim() == 2 ? "area " : "volume ") + std::to_string(measure(e)) + ")");
  }
}

}  // namespace snede
