#include "topology/degeneracy_removal.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_set>

#include "topology/collapse_edge.hpp"
#include "topology/dissect.hpp"
#include "topology/insert_vertex.hpp"
#include "topology/local_star.hpp"
#include "topology/split_edge.hpp"

namespace snede {
namespace {

// Passes stop when the list of degenerate elements did not shrink (§3.2.3), and after this many
// at most.
constexpr int max_passes = 8;

// Keeps splits away from the ends of an edge: there a collapse alone does the job.
constexpr double min_split_fraction = 0.05;

Eigen::Vector3d position(const Mesh& mesh, VertexId v) {
  const auto p = mesh.point(v);
  return {p[0], p[1], p[2]};
}

bool on_boundary(const Mesh& mesh, VertexId v) {
  const Connectivity& c = mesh.connectivity();
  for (ElementId e : local_star(c, v).elements)
    for (FaceId f : c.element(e).faces)
      if (c.face(f).mate == no_id && c.face(f).simplex.contains(v)) return true;
  return false;
}

// Where lines a→b and c→d pass closest: the fractions s along ab and t along cd.
std::pair<double, double> closest_fractions(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                            const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  const Eigen::Vector3d d1 = b - a, d2 = d - c, r = a - c;
  const double aa = d1.dot(d1), ab = d1.dot(d2), bb = d2.dot(d2), ar = d1.dot(r), br = d2.dot(r);
  const double denominator = aa * bb - ab * ab;
  if (!(denominator > 0)) return {-1, -1};
  return {(ab * br - bb * ar) / denominator, (aa * br - ab * ar) / denominator};
}

bool inside_edge(double t) { return t > min_split_fraction && t < 1 - min_split_fraction; }

using Corners = std::array<VertexId, max_dimension + 1>;

class Remover {
 public:
  Remover(Mesh& mesh, const DegeneracyOptions& options, DegeneracyReport& report)
      : mesh_(mesh), options_(options), report_(report) {}

  bool degenerate(ElementId e) const {
    return element_quality(3, mesh_.corners(e)).aspect_ratio < options_.min_aspect_ratio;
  }

  // Collapses edge (a, b), keeping the boundary end if only one is on the boundary.
  bool collapse(VertexId a, VertexId b) {
    const bool a_fixed = on_boundary(mesh_, a), b_fixed = on_boundary(mesh_, b);
    std::vector<std::pair<VertexId, VertexId>> tries;
    if (!b_fixed || a_fixed) tries.push_back({a, b});
    if (!a_fixed || b_fixed) tries.push_back({b, a});
    for (const auto& [keep, gone] : tries)
      if (collapse_edge(mesh_, keep, gone).done) {
        ++report_.edges_collapsed;
        return true;
      }
    return false;
  }

  // Collapses the shortest edge from `from` to one of `to` that can be collapsed.
  bool collapse_shortest(VertexId from, std::vector<VertexId> to) {
    std::sort(to.begin(), to.end(), [&](VertexId p, VertexId q) {
      return (position(mesh_, p) - position(mesh_, from)).norm() < (position(mesh_, q) - position(mesh_, from)).norm();
    });
    for (VertexId v : to)
      if (has_edge(mesh_.connectivity(), from, v) && collapse(v, from)) return true;
    return false;
  }

  bool remove_needle(const Corners& tet) {
    std::array<int, 6> order{0, 1, 2, 3, 4, 5};
    std::array<double, 6> length{};
    for (int k = 0; k < 6; ++k) {
      const auto [i, j] = tetrahedron_edges[k];
      length[k] = (position(mesh_, tet[i]) - position(mesh_, tet[j])).norm();
    }
    std::sort(order.begin(), order.end(), [&](int p, int q) { return length[p] < length[q]; });
    for (int k : {order[0], order[1]})
      if (collapse(tet[tetrahedron_edges[k][0]], tet[tetrahedron_edges[k][1]])) return true;
    return false;
  }

  // Splits (a, b) at t, then collapses the new vertex's shortest edge to one of `partners`;
  // undoes the split when no such collapse is possible.
  bool split_and_collapse(VertexId a, VertexId b, double t, const std::vector<VertexId>& partners) {
    const EditResult split = split_edge(mesh_, a, b, t);
    if (!split.done) return false;
    if (collapse_shortest(split.vertex, partners)) {
      created.push_back(split.vertex);
      ++report_.edges_split;
      return true;
    }
    collapse_edge(mesh_, a, split.vertex);  // restores the elements around (a, b)
    return false;
  }

  bool remove_spindle(const Corners& tet, int large_edge) {
    const auto [i, j] = tetrahedron_edges[large_edge];
    const auto [k, l] = tetrahedron_edges[5 - large_edge];  // the opposite edge
    const VertexId vi = tet[i], vj = tet[j], vk = tet[k], vl = tet[l];
    const double t = closest_fractions(position(mesh_, vk), position(mesh_, vl), position(mesh_, vi), position(mesh_, vj)).first;
    if (inside_edge(t) && split_and_collapse(vk, vl, t, {vi, vj})) return true;
    return remove_needle(tet);
  }

  bool remove_sliver(const Corners& tet, int first, int second) {
    if (first + second != 5) return remove_needle(tet);  // the large angles are not at opposite edges
    const VertexId vi = tet[tetrahedron_edges[first][0]], vj = tet[tetrahedron_edges[first][1]];
    const VertexId vk = tet[tetrahedron_edges[second][0]], vl = tet[tetrahedron_edges[second][1]];
    const auto [s, t] = closest_fractions(position(mesh_, vi), position(mesh_, vj), position(mesh_, vk), position(mesh_, vl));
    if (inside_edge(s) && inside_edge(t)) {
      const EditResult first_split = split_edge(mesh_, vi, vj, s);
      if (first_split.done) {
        if (split_and_collapse(vk, vl, t, {first_split.vertex})) {
          created.push_back(first_split.vertex);
          ++report_.edges_split;
          return true;
        }
        collapse_edge(mesh_, vi, first_split.vertex);
      }
    }
    return remove_needle(tet);
  }

  bool remove_cap(ElementId e, const Corners& order, const std::array<bool, 6>& large) {
    // The three large angles around one face: the corner opposite it sits above that face.
    for (int apex = 0; apex < 4; ++apex) {
      bool around_face = true;
      for (int k = 0; k < 6; ++k)
        if (large[k] && (tetrahedron_edges[k][0] == apex || tetrahedron_edges[k][1] == apex)) around_face = false;
      if (!around_face) continue;
      const VertexId top = order[apex];
      std::array<Eigen::Vector3d, 4> x;
      for (int k = 0; k < 4; ++k) x[k] = position(mesh_, order[k]);
      const int a = static_cast<int>(std::find(order.begin(), order.end(), top) - order.begin());
      // Barycentric coordinates of the apex's projection onto the opposite face.
      std::array<int, 3> face{};
      for (int k = 0, n = 0; k < 4; ++k)
        if (k != a) face[n++] = k;
      const Eigen::Vector3d normal = (x[face[1]] - x[face[0]]).cross(x[face[2]] - x[face[0]]);
      std::array<double, 4> weights{};
      double total = 0;
      for (int n = 0; n < 3; ++n) {
        const Eigen::Vector3d &p = x[face[(n + 1) % 3]], &q = x[face[(n + 2) % 3]];
        weights[face[n]] = (p - x[a]).cross(q - x[a]).dot(normal);
        total += weights[face[n]];
      }
      if (!(total > 0)) break;
      bool inside = true;
      for (int n = 0; n < 3; ++n) inside = inside && (weights[face[n]] /= total) > min_split_fraction;
      if (!inside) break;
      const EditResult insertion = insert_vertex(mesh_, e, weights);
      if (!insertion.done) break;
      if (collapse_shortest(insertion.vertex, {top})) {
        created.push_back(insertion.vertex);
        ++report_.faces_split;
        return true;
      }
      collapse_edge(mesh_, order[face[0]], insertion.vertex);  // restores the two tetrahedra
      break;
    }
    return remove_needle(order);
  }

  bool remove(ElementId e) {
    // Corner k of mesh.corners(e), the order dihedral_angles and tetrahedron_edges use.
    const Corners tet = mesh_.connectivity().element(e).simplex.oriented_vertices();
    const std::array<double, 6> angles = dihedral_angles(mesh_.corners(e));
    std::array<bool, 6> large{};
    std::vector<int> at;
    for (int k = 0; k < 6; ++k)
      if ((large[k] = angles[k] > options_.large_angle)) at.push_back(k);
    switch (at.size()) {
      case 0: return remove_needle(tet);
      case 1: return remove_spindle(tet, at[0]);
      case 2: return remove_sliver(tet, at[0], at[1]);
      default: return remove_cap(e, tet, large);
    }
  }

  // Dissects e along its interior faces, so that it is a piece of its own, and removes it
  // with the vertices only it used.
  void cut_free(ElementId e) {
    Connectivity& c = mesh_.connectivity();
    ChangeBatch batch(c);
    std::vector<FaceId> inner;
    for (FaceId f : c.element(e).faces)
      if (c.face(f).mate != no_id) inner.push_back(f);
    if (!inner.empty())
      dissect(c, inner, [this](VertexId v) { return mesh_.add_vertex(VertexParents::copy_of(v)); });
    const Simplex tet = c.element(e).simplex;
    const std::array<ElementId, 1> gone{e};
    c.replace_elements(gone, {});
    for (VertexId v : tet.vertices())
      if (c.n_vertex_uses(v) == 0) mesh_.remove_vertex(v);
    ++report_.cut_free;
  }

  std::vector<VertexId> created;  // vertices added by kept splits and insertions (some collapsed since)

 private:
  Mesh& mesh_;
  const DegeneracyOptions& options_;
  DegeneracyReport& report_;
};

}  // namespace

DegenerateShape degenerate_shape(std::span<const double> corners, double large_angle) {
  const std::array<double, 6> angles = dihedral_angles(corners);
  const auto large = std::count_if(angles.begin(), angles.end(), [&](double a) { return a > large_angle; });
  return static_cast<DegenerateShape>(std::min<long>(large, 3));
}

DegeneracyReport remove_degeneracies(Mesh& mesh, const std::vector<VertexId>& region, const DegeneracyOptions& options) {
  if (mesh.cell_dim() != 3 || mesh.space_dim() != 3)
    throw std::invalid_argument("remove_degeneracies: the mesh must be tetrahedral");
  if (!(options.min_aspect_ratio > 0 && options.min_aspect_ratio < 1))
    throw std::invalid_argument("remove_degeneracies: min_aspect_ratio must be in (0, 1), got " +
                                std::to_string(options.min_aspect_ratio));
  if (!(options.large_angle > 0 && options.large_angle < std::numbers::pi))
    throw std::invalid_argument("remove_degeneracies: large_angle must be in (0, π), got " +
                                std::to_string(options.large_angle));
  DegeneracyReport report;
  Remover remover(mesh, options, report);
  std::unordered_set<VertexId> around(region.begin(), region.end());
  const Connectivity& c = mesh.connectivity();

  // The degenerate elements near the region; vertices the removal creates join the region.
  auto list = [&]() {
    std::vector<ElementId> found;
    std::unordered_set<ElementId> seen;
    for (VertexId v : around)
      if (mesh.is_vertex(v))
        for (ElementId e : local_star(c, v).elements)
          if (seen.insert(e).second && remover.degenerate(e)) found.push_back(e);
    // Caps first, then slivers, spindles and needles, the flattest first within a class: a cap's
    // neighbours are often slivers that its removal repairs, while their splits would cut the
    // cap into degenerate pieces.
    std::vector<std::tuple<int, double, ElementId>> order;
    for (ElementId e : found) {
      const std::vector<double> x = mesh.corners(e);
      order.push_back({-static_cast<int>(degenerate_shape(x, options.large_angle)), element_quality(3, x).aspect_ratio, e});
    }
    std::sort(order.begin(), order.end());
    for (std::size_t i = 0; i < found.size(); ++i) found[i] = std::get<2>(order[i]);
    return found;
  };
  std::vector<ElementId> degenerate = list();
  report.found = static_cast<int>(degenerate.size());
  for (ElementId e : degenerate) ++report.by_shape[static_cast<int>(degenerate_shape(mesh.corners(e), options.large_angle))];
  while (!degenerate.empty() && report.passes < max_passes) {
    ++report.passes;
    for (ElementId e : degenerate) {
      if (!c.is_element(e) || !remover.degenerate(e)) continue;  // gone or repaired by an earlier collapse
      for (VertexId v : c.element(e).simplex.vertices()) around.insert(v);
      remover.remove(e);
    }
    around.insert(remover.created.begin(), remover.created.end());
    remover.created.clear();
    std::vector<ElementId> next = list();
    const bool shorter = next.size() < degenerate.size();
    degenerate = std::move(next);
    if (!shorter) break;
  }
  for (ElementId e : degenerate)
    if (c.is_element(e) && remover.degenerate(e)) remover.cut_free(e);
  return report;
}

}  // namespace snede
