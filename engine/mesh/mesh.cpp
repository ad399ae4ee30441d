#include "mesh/mesh.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "mesh/traversal.hpp"
#include "mesh/validate.hpp"

namespace snede {
namespace {

// A cell is degenerate when |V| ≤ this · (longest edge)^dim: a few ulps of the scale, so
// that thin but real elements (aspect ratio 1e-6) are kept.
constexpr double zero_volume_tolerance = 64 * std::numeric_limits<double>::epsilon();

std::vector<double> gather_corners(int dim, const std::vector<double>& points, std::span<const VertexId> cell) {
  std::vector<double> corners;
  corners.reserve(cell.size() * dim);
  for (VertexId v : cell)
    for (int k = 0; k < dim; ++k) corners.push_back(points[static_cast<std::size_t>(v) * dim + k]);
  return corners;
}

std::vector<VertexId> checked_oriented_cells(int dim, const std::vector<double>& points,
                                             std::span<const std::int64_t> given, std::size_t& n_reoriented) {
  const int nv = dim + 1;
  const auto n_points = static_cast<std::int64_t>(points.size() / dim);
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
    const std::vector<double> corners = gather_corners(dim, points, cell);
    const double volume = signed_volume(dim, corners);
    const double scale = std::pow(longest_edge(dim, corners), dim);
    if (!(std::abs(volume) > zero_volume_tolerance * scale)) {
      std::ostringstream message;
      message << "cell " << c << " has zero " << (dim == 2 ? "area" : "volume") << " (" << volume
              << " for a longest edge of " << std::pow(scale, 1.0 / dim) << ")";
      throw std::invalid_argument(message.str());
    }
    if (volume < 0) {
      std::swap(cell[0], cell[1]);
      ++n_reoriented;
    }
  }
  return cells;
}

}  // namespace

Mesh::Mesh(int dim, std::vector<double> points, std::span<const std::int64_t> cells)
    : dim_(dim), points_(std::move(points)), connectivity_(dim) {
  if (dim != 2 && dim != 3) throw std::invalid_argument("mesh dimension must be 2 or 3, got " + std::to_string(dim));
  if (points_.size() % dim != 0 || cells.size() % (dim + 1) != 0)
    throw std::invalid_argument("points must be (n, " + std::to_string(dim) + ") and cells (m, " +
                                std::to_string(dim + 1) + ")");
  if (points_.size() / dim > static_cast<std::size_t>(std::numeric_limits<VertexId>::max()))
    throw std::invalid_argument("too many points for 32-bit vertex ids");
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (!std::isfinite(points_[i])) {
      std::ostringstream message;
      message << "point " << i / dim << " has a non-finite coordinate (" << points_[i] << ")";
      throw std::invalid_argument(message.str());
    }
  connectivity_ = Connectivity::from_cells(dim, checked_oriented_cells(dim, points_, cells, n_reoriented_));
  n_initial_points_ = n_points();
}

std::vector<VertexId> Mesh::cells() const {
  std::vector<VertexId> cells;
  cells.reserve(n_cells() * (dim_ + 1));
  for (ElementId e : connectivity_.element_ids()) {
    const auto oriented = connectivity_.element(e).simplex.oriented_vertices();
    cells.insert(cells.end(), oriented.begin(), oriented.begin() + dim_ + 1);
  }
  return cells;
}

std::vector<ElementId> Mesh::cell_ids() const { return connectivity_.element_ids(); }

std::vector<double> Mesh::corners(ElementId e) const {
  const auto oriented = connectivity_.element(e).simplex.oriented_vertices();
  return gather_corners(dim_, points_, std::span<const VertexId>(oriented.data(), dim_ + 1));
}

std::vector<ElementQuality> Mesh::quality() const {
  std::vector<ElementQuality> q;
  q.reserve(n_cells());
  for (ElementId e : connectivity_.element_ids()) q.push_back(element_quality(dim_, corners(e)));
  return q;
}

std::vector<VertexId> Mesh::boundary_faces() const {
  std::vector<VertexId> faces;
  for (FaceId f : snede::boundary_faces(connectivity_)) {
    const auto oriented = connectivity_.face(f).simplex.oriented_vertices();
    faces.insert(faces.end(), oriented.begin(), oriented.begin() + dim_);
  }
  return faces;
}

std::vector<FaceId> Mesh::find_faces(const std::vector<VertexId>& face_vertices) const {
  if (face_vertices.size() % dim_ != 0)
    throw std::invalid_argument("faces must be (n, " + std::to_string(dim_) + ") vertex ids");
  // Keyed by the vertex set (positive orientation), so a boundary face of either sign is found.
  auto unsigned_key = [](const Simplex& s) { return s.sign() > 0 ? s : s.mate(); };
  std::unordered_map<Simplex, FaceId, SimplexHash> wanted;
  for (std::size_t i = 0; i < face_vertices.size() / dim_; ++i)
    wanted.emplace(unsigned_key(Simplex(1, std::span<const VertexId>(face_vertices.data() + i * dim_, dim_))), no_id);
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

std::vector<SplitVertex> Mesh::dissect(const std::vector<VertexId>& face_vertices) {
  const std::vector<FaceId> faces = find_faces(face_vertices);
  return snede::dissect(connectivity_, faces, [this](VertexId original) {
    VertexParents copy_of;
    copy_of.vertex[0] = original;
    copy_of.weight[0] = 1.0;
    copy_of.count = 1;
    return add_vertex(copy_of);
  });
}

VertexId Mesh::add_vertex(const VertexParents& parents) {
  if (parents.count < 1 || parents.count > 2) throw std::invalid_argument("add_vertex: needs one or two parents");
  const VertexId v = n_points();
  for (int k = 0; k < dim_; ++k) {
    double x = 0;
    for (int i = 0; i < parents.count; ++i) {
      if (parents.vertex[i] < 0 || parents.vertex[i] >= v)
        throw std::invalid_argument("add_vertex: parent " + std::to_string(parents.vertex[i]) + " does not exist");
      x += parents.weight[i] * points_[static_cast<std::size_t>(parents.vertex[i]) * dim_ + k];
    }
    points_.push_back(x);
  }
  added_parents_.push_back(parents);
  return v;
}

VertexParents Mesh::parents(VertexId v) const {
  return v < n_initial_points_ ? VertexParents{} : added_parents_.at(v - n_initial_points_);
}

void Mesh::validate() const {
  if (auto violation = find_violation(connectivity_)) throw InvalidMesh(*violation);
  for (ElementId e : connectivity_.element_ids()) {
    const Simplex& s = connectivity_.element(e).simplex;
    for (VertexId v : s.vertices())
      if (v >= n_points())
        throw InvalidMesh("element " + std::to_string(e) + " " + s.to_string() + " uses vertex " +
                          std::to_string(v) + " beyond the " + std::to_string(n_points()) + " points");
    if (!(signed_volume(dim_, corners(e)) > 0))
      throw InvalidMesh("element " + std::to_string(e) + " " + s.to_string() + " is not positively oriented");
  }
}

}  // namespace snede
