#include "cutting/tetrahedral_cutter.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "core/predicates.hpp"
#include "cutting/node_snapping.hpp"
#include "topology/dissect.hpp"
#include "topology/local_star.hpp"

namespace snede {
namespace {

// The face of c oriented as σ (interior or boundary), or no_id.
FaceId face_of(const Connectivity& c, const Simplex& sigma) {
  for (ElementId e : local_star(c, sigma.vertex(0)).elements)
    for (FaceId f : c.element(e).faces)
      if (f != no_id && c.face(f).simplex == sigma) return f;
  return no_id;
}

// The tetrahedron of c whose simplex is σ, or no_id.
ElementId element_of(const Connectivity& c, const Simplex& sigma) {
  for (ElementId e : local_star(c, sigma.vertex(0)).elements)
    if (c.element(e).simplex == sigma) return e;
  return no_id;
}

}  // namespace

TetrahedralCutter::TetrahedralCutter(Mesh& mesh, CutBody body, CutterOptions options)
    : mesh_(mesh), body_(std::move(body)), options_(options), pieces_(mesh.connectivity()) {
  if (mesh.cell_dim() != 3 || mesh.space_dim() != 3)
    throw std::invalid_argument("TetrahedralCutter: the mesh must be tetrahedral (3D cells in 3D), got cell_dim " +
                                std::to_string(mesh.cell_dim()) + " in " + std::to_string(mesh.space_dim()) + "D");
  const DegeneracyOptions& d = options.degeneracy;
  if (!(d.min_aspect_ratio > 0 && d.min_aspect_ratio < 1))
    throw std::invalid_argument("TetrahedralCutter: min_aspect_ratio must be in (0, 1), got " + std::to_string(d.min_aspect_ratio));
  if (!(d.large_angle > 0 && d.large_angle < std::acos(-1.0)))
    throw std::invalid_argument("TetrahedralCutter: large_angle must be in (0, π), got " + std::to_string(d.large_angle));
  mesh_.connectivity().add_watcher(this);
}

TetrahedralCutter::~TetrahedralCutter() { mesh_.connectivity().remove_watcher(this); }

DeformedPositions TetrahedralCutter::cut_positions() const {
  return DeformedPositions(mesh_, cut_configuration_);
}

std::vector<double> TetrahedralCutter::displacement_now() const {
  const DisplacementRead u = body_.displacement();
  return {u.values.begin(), u.values.end()};
}

bool TetrahedralCutter::constrained(VertexId v) const {
  return body_.is_support && body_.is_support(v);
}

std::optional<ExclusiveUse::Claim> TetrahedralCutter::claim_body() const {
  if (!body_.exclusive_use) return std::nullopt;
  return body_.exclusive_use->claim("a cut");
}

CutResult TetrahedralCutter::cut_triangle(std::span<const double> corners) {
  const SweepTriangle sweep(corners);  // validates before anything changes
  const auto claim = claim_body();
  if (!cut_configuration_.empty() || !body_.displacement) return cut(sweep);
  // A sweep triangle given alone (not by a move of the placed scalpel) meets the body as it is.
  cut_configuration_ = displacement_now();
  try {
    CutResult report = cut(sweep);
    cut_configuration_.clear();
    return report;
  } catch (...) {
    cut_configuration_.clear();
    throw;
  }
}

CutResult TetrahedralCutter::cut(const SweepTriangle& sweep) {
  const double start = wall_seconds();
  CutResult report;
  report.sweeps = 1;
  report.components = pieces_.pieces();

  FaceSelection selection = selector_.select(mesh_.connectivity(), cut_positions(), sweep);
  // Faces selected earlier but left joined by their dissection are cut again with the new ones.
  for (const auto& [f, simplex] : joined_) {
    const Connectivity& c = mesh_.connectivity();
    if (c.is_face(f) && c.face(f).simplex == simplex && c.face(f).mate != no_id) selection.faces.push_back(f);
  }
  std::sort(selection.faces.begin(), selection.faces.end());
  selection.faces.erase(std::unique(selection.faces.begin(), selection.faces.end()), selection.faces.end());
  report.faces_selected = static_cast<int>(selection.faces.size());

  if (!selection.faces.empty()) {
    std::vector<VertexId> region;
    if (options_.snap) region = snap(selection, report);
    {
      ChangeBatch batch(mesh_.connectivity());
      const std::vector<VertexId> cut = dissect_selected(selection.faces, report);
      region.insert(region.end(), cut.begin(), cut.end());
      if (options_.remove_degeneracies && !region.empty()) {
        const DegeneracyReport d = remove_degeneracies(mesh_, region, options_.degeneracy);
        report.degenerate_found = d.found;
        report.degenerate_shapes = d.by_shape;
        report.edges_collapsed = d.edges_collapsed;
        report.edges_split = d.edges_split;
        report.faces_split = d.faces_split;
        report.elements_cut_free = d.cut_free;
      }
    }
    count_pieces(report);
  }
  report.seconds = wall_seconds() - start;
  return report;
}

std::vector<VertexId> TetrahedralCutter::snap(const FaceSelection& selection, CutResult& report) {
  std::vector<VertexId> snapped;
  std::vector<VertexId> vertices;
  for (FaceId f : selection.faces)
    for (VertexId v : mesh_.connectivity().face(f).simplex.vertices()) vertices.push_back(v);
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  // Each snap moves its vertex before the next is tried, so the order decides which of two
  // neighbours is refused: an order by where the vertices are (their reference coordinates, then
  // their ids for vertices at one place, a cut's copies), not by how the mesh numbers them, so that
  // a renumbered copy of the mesh (a distributed body's cutting rank, issue 52) snaps alike.
  std::sort(vertices.begin(), vertices.end(), [&](VertexId a, VertexId b) {
    const auto x = mesh_.point(a), y = mesh_.point(b);
    return std::lexicographical_compare(x.begin(), x.end(), y.begin(), y.end()) ||
           (std::equal(x.begin(), x.end(), y.begin()) && a < b);
  });
  for (VertexId v : vertices) {
    if (placed_.count(v)) continue;
    if (constrained(v)) {  // a support stays where the user put it
      ++report.snaps_refused;
      continue;
    }
    const auto plane = selection.plane.find(v);
    if (plane == selection.plane.end()) continue;  // a vertex of a face selected by an earlier sweep
    // u read again for every vertex: each snap moves the one before.
    const DisplacementRead u = body_.displacement ? body_.displacement() : DisplacementRead{};
    const DeformedPositions now(mesh_, u.values);
    const EditResult result = snap_to_sweep(mesh_, cut_positions(), v, plane->second, &now);
    if (result.done) {
      ++report.vertices_snapped;
      placed_.insert(v);
      snapped.push_back(v);
    } else {
      ++report.snaps_refused;
    }
  }
  return snapped;
}

std::vector<VertexId> TetrahedralCutter::dissect_selected(std::vector<FaceId> faces, CutResult& report) {
  Connectivity& c = mesh_.connectivity();
  std::vector<FaceId> mates;
  for (FaceId f : faces) mates.push_back(c.face(f).mate);
  const std::vector<SplitVertex> split =
      dissect(c, faces, [this](VertexId v) { return mesh_.add_vertex(VertexParents::copy_of(v)); });
  report.vertices_split = static_cast<int>(split.size());
  joined_.clear();
  std::vector<VertexId> region;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Face& face = c.face(faces[i]);
    if (face.mate != no_id) {
      joined_.push_back({faces[i], face.simplex});
      continue;
    }
    ++report.faces_dissected;
    for (FaceId side : {faces[i], mates[i]}) incision_[side] = c.face(side).simplex;
    for (VertexId v : face.simplex.vertices()) region.push_back(v), placed_.insert(v);
  }
  for (const SplitVertex& s : split) {
    placed_.insert(s.copy);
    region.push_back(s.copy);
  }
  return region;
}

bool TetrahedralCutter::remove_fragments(CutResult& report) {
  Connectivity& c = mesh_.connectivity();
  // By volume: degeneracy removal splits elements, so a sliver can be several tiny ones.
  std::vector<double> volume(pieces_.pieces(), 0.0);
  double total = 0;
  for (ElementId e : c.element_ids()) {
    const double v = mesh_.measure(e);
    volume[pieces_.label(e)] += v;
    total += v;
  }
  const double limit = options_.max_fragment_elements * total / static_cast<double>(c.n_elements());
  const int largest = static_cast<int>(std::max_element(volume.begin(), volume.end()) - volume.begin());
  const auto fragment = [&](int piece) { return piece != largest && volume[piece] <= limit; };
  std::vector<ElementId> doomed;
  for (ElementId e : c.element_ids())
    if (fragment(pieces_.label(e))) doomed.push_back(e);
  if (doomed.empty()) return false;
  for (int piece = 0; piece < static_cast<int>(volume.size()); ++piece) report.fragments_removed += fragment(piece);
  report.fragment_elements = static_cast<int>(doomed.size());
  std::vector<VertexId> corners;
  for (ElementId e : doomed)
    for (VertexId v : c.element(e).simplex.vertices()) corners.push_back(v);
  ChangeBatch batch(c);
  c.replace_elements(doomed, {});
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  for (VertexId v : corners)
    if (c.n_vertex_uses(v) == 0) mesh_.remove_vertex(v);
  return true;
}

void TetrahedralCutter::count_pieces(CutResult& report) {
  const Connectivity& c = mesh_.connectivity();
  bool separated = pieces_.update(c);
  if (separated && options_.max_fragment_elements > 0 && remove_fragments(report)) {
    pieces_ = PieceTracker(c);  // whole pieces went: count again (O(n), only after a fragment)
    separated = pieces_.pieces() > 1;
  }
  report.piece_search = pieces_.last_search_size();
  report.components = pieces_.pieces();
  if (separated) {
    report.piece_elements.assign(pieces_.pieces(), 0);
    for (ElementId e : c.element_ids()) ++report.piece_elements[pieces_.label(e)];
    std::sort(report.piece_elements.rbegin(), report.piece_elements.rend());
  }
  if (!separated || !body_.free_pieces) return;  // a bare mesh has no supports to be free of
  for (ElementId cell : body_.free_pieces()) {
    ++report.free_pieces;
    if (!options_.fix_free_pieces || !body_.hold_free_piece) continue;
    // §3.3: held on one face, so that the static problem stays well posed.
    const Simplex face = c.element(cell).simplex.subn(0);
    const std::vector<VertexId> vertices(face.vertices().begin(), face.vertices().end());
    body_.hold_free_piece(vertices);
    ++report.pieces_fixed;
  }
}

CutResult TetrahedralCutter::move(std::span<const double> scalpel) {
  if (scalpel.size() != 6)
    throw std::invalid_argument("TetrahedralCutter.move: the scalpel is a segment, (2, 3) coordinates; got " +
                                std::to_string(scalpel.size()) + " numbers");
  require_finite_points(scalpel.data(), scalpel.size(), 3, "TetrahedralCutter.move", "scalpel end");
  std::array<double, 6> now;
  std::copy(scalpel.begin(), scalpel.end(), now.begin());
  if (now[0] == now[3] && now[1] == now[4] && now[2] == now[5])
    throw std::invalid_argument("TetrahedralCutter.move: the scalpel's two ends coincide (a segment of zero length)");
  const auto claim = claim_body();
  CutResult report;
  if (!scalpel_ && body_.displacement) cut_configuration_ = displacement_now();
  if (scalpel_) {
    const std::array<double, 6>& was = *scalpel_;
    // The quadrilateral p0 p1 q1 q0 swept from (p0, p1) to (q0, q1), as two triangles.
    const std::array<std::array<double, 9>, 2> halves{{
        {was[0], was[1], was[2], was[3], was[4], was[5], now[3], now[4], now[5]},
        {was[0], was[1], was[2], now[3], now[4], now[5], now[0], now[1], now[2]},
    }};
    for (const auto& triangle : halves) {
      const std::array<const double*, 3> p{triangle.data(), triangle.data() + 3, triangle.data() + 6};
      if (collinear_3d(p[0], p[1], p[2])) continue;  // this half swept no area
      report.add(cut(SweepTriangle(triangle)));
    }
  }
  scalpel_ = now;
  report.components = pieces_.pieces();
  return report;
}

void TetrahedralCutter::lift() {
  scalpel_.reset();
  cut_configuration_.clear();
  selector_.forget();
  joined_.clear();
}

std::vector<VertexId> TetrahedralCutter::incision_faces() const {
  const Connectivity& c = mesh_.connectivity();
  std::vector<VertexId> faces;
  for (const auto& [f, simplex] : incision_) {
    if (!c.is_face(f) || c.face(f).simplex != simplex || c.face(f).mate != no_id) continue;
    const auto corners = simplex.oriented_vertices();
    faces.insert(faces.end(), corners.begin(), corners.begin() + 3);
  }
  return faces;
}

void TetrahedralCutter::on_change(const Connectivity& c, const ConnectivityChange& change) {
  pieces_.on_change(c, change);
  if (!cut_configuration_.empty()) {
    cut_configuration_.resize(3 * static_cast<std::size_t>(mesh_.n_points()), 0.0);
    replay_vertex_events(cut_configuration_, 3, change.vertex_events);
  }
  // The older vertices each vertex this change added lies between (its parents, or theirs if
  // they were added too); ids removed in the change may come back as other vertices.
  std::unordered_map<VertexId, std::vector<VertexId>> made_from;
  for (const VertexEvent& event : change.vertex_events) {
    if (event.kind == VertexEventKind::removed) {
      placed_.erase(event.vertex);
      made_from.erase(event.vertex);
    }
    if (event.kind != VertexEventKind::added) continue;
    std::vector<VertexId> from;
    for (std::size_t k = 0; k < event.parents.count(); ++k) {
      if (event.parents.weight[k] == 0) continue;
      const VertexId p = event.parents.vertex[k];
      const auto earlier = made_from.find(p);
      if (earlier == made_from.end()) from.push_back(p);
      else from.insert(from.end(), earlier->second.begin(), earlier->second.end());
    }
    std::sort(from.begin(), from.end());
    from.erase(std::unique(from.begin(), from.end()), from.end());
    made_from[event.vertex] = std::move(from);
  }
  // A face whose vertices were substituted (a collapse) leaves the boundary under its old
  // simplex and returns under its new one: the incision follows it.
  std::unordered_set<Simplex, SimplexHash> left(change.boundary_removed.begin(), change.boundary_removed.end());
  std::vector<Simplex> left_incision;
  for (const auto& [f, simplex] : incision_)
    if (left.count(simplex)) left_incision.push_back(simplex);
  for (FaceId f : change.boundary_added)
    if (const auto it = incision_.find(f); it != incision_.end() && left.count(it->second)) it->second = c.face(f).simplex;
  std::erase_if(incision_, [&](const auto& entry) { return !c.is_face(entry.first) || c.face(entry.first).simplex != entry.second; });
  // A boundary face made inside an incision face that left the boundary (a bisection or split
  // of it, §6.5): all its vertices lie between that face's vertices, and it is on the incision.
  if (left_incision.empty()) return;
  for (FaceId f : change.boundary_added) {
    if (!c.is_face(f) || c.face(f).mate != no_id || incision_.count(f)) continue;
    std::vector<VertexId> from;
    for (VertexId v : c.face(f).simplex.vertices()) {
      const auto made = made_from.find(v);
      if (made == made_from.end()) from.push_back(v);
      else from.insert(from.end(), made->second.begin(), made->second.end());
    }
    const bool inside = std::any_of(left_incision.begin(), left_incision.end(), [&](const Simplex& sigma) {
      return std::all_of(from.begin(), from.end(), [&](VertexId v) { return sigma.contains(v); });
    });
    if (inside) incision_[f] = c.face(f).simplex;
  }
}

CutterMemory TetrahedralCutter::memory() const {
  const Connectivity& c = mesh_.connectivity();
  CutterMemory memory{.scalpel = scalpel_, .cut_configuration = cut_configuration_,
                      .placed = {placed_.begin(), placed_.end()}, .joined = {}, .incision = {}, .sweeps = {},
                      .previous_touched = {}};
  std::sort(memory.placed.begin(), memory.placed.end());
  for (const auto& [f, simplex] : joined_) memory.joined.push_back(simplex);
  for (const auto& [f, simplex] : incision_) memory.incision.push_back(simplex);
  std::sort(memory.incision.begin(), memory.incision.end());
  for (const SweepTriangle& sweep : selector_.remembered()) {
    std::array<double, 9> corners{};
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) corners[static_cast<std::size_t>(3 * i + k)] = sweep.corner(i)[k];
    memory.sweeps.push_back(corners);
  }
  for (ElementId e : selector_.previous_touched())
    if (c.is_element(e)) memory.previous_touched.push_back(c.element(e).simplex);
  return memory;
}

void TetrahedralCutter::restore(const CutterMemory& memory) {
  const Connectivity& c = mesh_.connectivity();
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("TetrahedralCutter.restore: " + what);
  };
  const auto check_vertices = [&](const Simplex& sigma, const char* what) {
    for (VertexId v : sigma.vertices())
      if (!mesh_.is_vertex(v)) fail(std::string(what) + " " + sigma.to_string() + " has no live vertex " + std::to_string(v));
  };
  if (!memory.cut_configuration.empty() && memory.cut_configuration.size() != 3 * static_cast<std::size_t>(mesh_.n_points()))
    fail("the cut configuration has " + std::to_string(memory.cut_configuration.size()) + " values, the mesh " +
         std::to_string(mesh_.n_points()) + " rows of 3");
  for (VertexId v : memory.placed)
    if (!mesh_.is_vertex(v)) fail("placed vertex " + std::to_string(v) + " is not a live vertex");
  std::vector<std::pair<FaceId, Simplex>> joined;
  std::unordered_map<FaceId, Simplex> incision;
  for (const auto& [simplexes, what] : {std::pair{&memory.joined, "joined face"}, std::pair{&memory.incision, "incision face"}})
    for (const Simplex& sigma : *simplexes) {
      check_vertices(sigma, what);
      const FaceId f = face_of(c, sigma);
      if (f == no_id) fail(std::string("the mesh has no ") + what + " " + sigma.to_string());
      if (simplexes == &memory.joined) joined.emplace_back(f, sigma);
      else incision.emplace(f, sigma);
    }
  std::vector<ElementId> touched;
  for (const Simplex& sigma : memory.previous_touched) {
    check_vertices(sigma, "tetrahedron");
    const ElementId e = element_of(c, sigma);
    if (e == no_id) fail("the mesh has no tetrahedron " + sigma.to_string());
    touched.push_back(e);
  }
  std::deque<SweepTriangle> sweeps;
  for (const auto& corners : memory.sweeps) sweeps.emplace_back(corners);
  scalpel_ = memory.scalpel;
  cut_configuration_ = memory.cut_configuration;
  placed_ = {memory.placed.begin(), memory.placed.end()};
  joined_ = std::move(joined);
  incision_ = std::move(incision);
  selector_.restore(std::move(sweeps), std::move(touched));
}

}  // namespace snede
