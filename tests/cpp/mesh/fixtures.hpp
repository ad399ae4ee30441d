// Small meshes and a recording watcher shared by the connectivity tests.
#pragma once

#include <map>
#include <set>
#include <vector>

#include "mesh/connectivity.hpp"

namespace snede::testing {

// Cells listed as positively oriented vertex sequences.
inline Connectivity connectivity_of(int dim, const std::vector<std::vector<VertexId>>& cells) {
  std::vector<VertexId> flat;
  for (const auto& cell : cells) flat.insert(flat.end(), cell.begin(), cell.end());
  return Connectivity::from_cells(dim, flat);
}

// nx × ny squares, each split into two consistently oriented triangles.
inline std::vector<std::vector<VertexId>> grid_triangles(int nx, int ny) {
  std::vector<std::vector<VertexId>> cells;
  auto v = [ny](int i, int j) { return i * (ny + 1) + j; };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      cells.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1)});
      cells.push_back({v(i, j), v(i + 1, j + 1), v(i, j + 1)});
    }
  return cells;
}

// n × n × n cubes, Kuhn split into six tetrahedra each, consistently oriented.
inline std::vector<std::vector<VertexId>> kuhn_box(int n) {
  std::vector<std::vector<VertexId>> cells;
  auto v = [n](int i, int j, int k) { return (i * (n + 1) + j) * (n + 1) + k; };
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  const bool odd[6] = {false, true, true, false, false, true};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (int p = 0; p < 6; ++p) {
          int corner[3] = {0, 0, 0};
          std::vector<VertexId> path{v(i, j, k)};
          for (int axis : permutations[p]) {
            corner[axis] = 1;
            path.push_back(v(i + corner[0], j + corner[1], k + corner[2]));
          }
          if (odd[p]) std::swap(path[2], path[3]);
          cells.push_back(path);
        }
  return cells;
}

inline VertexId max_vertex(const std::vector<std::vector<VertexId>>& cells) {
  VertexId m = 0;
  for (const auto& cell : cells)
    for (VertexId v : cell) m = std::max(m, v);
  return m;
}

// Rebuilds the element set and boundary only from what watchers are told, so tests can
// compare it with the connectivity itself (§7.4).
struct RecordingWatcher : ConnectivityWatcher {
  std::map<ElementId, Simplex> elements;
  std::set<Simplex> boundary;
  int n_changes = 0;

  void init(const Connectivity& c) override {
    elements.clear();
    boundary.clear();
    for (ElementId e : c.element_ids()) elements[e] = c.element(e).simplex;
    for (const auto& entry : c.boundary()) boundary.insert(entry.first);
  }
  void on_change(const Connectivity& c, const ConnectivityChange& change) override {
    ++n_changes;
    for (const auto& [e, old] : change.removed_elements) {
      if (elements.at(e) != old) throw std::logic_error("removed element had another simplex");
      elements.erase(e);
    }
    for (const auto& [e, old] : change.changed_elements) {
      if (elements.at(e) != old) throw std::logic_error("changed element had another simplex");
      elements[e] = c.element(e).simplex;
    }
    for (ElementId e : change.added_elements) elements[e] = c.element(e).simplex;
    for (const Simplex& s : change.boundary_removed) boundary.erase(s);
    for (FaceId f : change.boundary_added) boundary.insert(c.face(f).simplex);
  }
  bool matches(const Connectivity& c) const {
    std::map<ElementId, Simplex> actual;
    for (ElementId e : c.element_ids()) actual[e] = c.element(e).simplex;
    std::set<Simplex> actual_boundary;
    for (const auto& entry : c.boundary()) actual_boundary.insert(entry.first);
    return actual == elements && actual_boundary == boundary;
  }
};

}  // namespace snede::testing
