#include "mesh/piece_tracker.hpp"

#include <algorithm>
#include <numeric>

#include "mesh/traversal.hpp"

namespace snede {

PieceTracker::PieceTracker(const Connectivity& c) { relabel(c); }

void PieceTracker::relabel(const Connectivity& c) {
  auto [label, n] = connected_components(c);
  label_ = std::move(label);
  pieces_ = n;
  stale_ = false;
  changed_.clear();
}

void PieceTracker::on_change(const Connectivity& c, const ConnectivityChange& change) {
  label_.resize(c.element_capacity(), -1);
  for (const auto& [e, simplex] : change.removed_elements) label_[e] = -1;
  for (ElementId e : change.added_elements) label_[e] = -1;
  // An added element takes the label of a labelled neighbour; chains of added elements are
  // labelled from their ends inward. Neighbours of two labels would mean pieces joined.
  std::vector<ElementId> unlabelled = change.added_elements;
  bool progress = true;
  while (!unlabelled.empty() && progress) {
    progress = false;
    std::vector<ElementId> still;
    for (ElementId e : unlabelled) {
      int found = -1;
      for (int j = 0; j <= c.dim(); ++j) {
        const ElementId n = c.neighbor(e, j);
        if (n == no_id || label_[n] < 0) continue;
        if (found >= 0 && found != label_[n]) stale_ = true;
        found = label_[n];
      }
      if (found >= 0) {
        label_[e] = found;
        progress = true;
      } else {
        still.push_back(e);
      }
    }
    unlabelled = std::move(still);
  }
  if (!unlabelled.empty()) stale_ = true;  // a new element with no old neighbour: start over
  // A changed element may now meet another piece through a face it took over (an edge
  // collapse): pieces joined, so the labels start over.
  for (const auto& [e, simplex] : change.changed_elements)
    for (int j = 0; j <= c.dim() && !stale_; ++j) {
      const ElementId n = c.neighbor(e, j);
      if (n != no_id && label_[n] >= 0 && label_[e] >= 0 && label_[n] != label_[e]) stale_ = true;
    }

  changed_.insert(changed_.end(), change.added_elements.begin(), change.added_elements.end());
  for (const auto& [e, simplex] : change.changed_elements) changed_.push_back(e);
  for (FaceId f : change.boundary_added)
    if (c.is_face(f)) changed_.push_back(c.face(f).element);
  // Changes heard for long without an update (a solver that stopped asking): counting again will
  // cost no more than searching from all of them.
  if (changed_.size() > static_cast<std::size_t>(c.element_capacity())) {
    stale_ = true;
    changed_.clear();
  }
}

bool PieceTracker::update(const Connectivity& c) {
  last_search_size_ = 0;
  if (stale_) {
    relabel(c);
    return true;
  }
  std::vector<ElementId> seeds;
  for (ElementId e : changed_)
    if (c.is_element(e)) seeds.push_back(e);
  changed_.clear();
  std::sort(seeds.begin(), seeds.end(), [this](ElementId a, ElementId b) {
    return label_[a] != label_[b] ? label_[a] < label_[b] : a < b;
  });
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  for (auto first = seeds.begin(); first != seeds.end();) {
    const auto last = std::find_if(first, seeds.end(), [&](ElementId e) { return label_[e] != label_[*first]; });
    if (last - first > 1 && splits(c, std::vector<ElementId>(first, last))) {
      relabel(c);
      return true;
    }
    first = last;
  }
  return false;
}

bool PieceTracker::splits(const Connectivity& c, const std::vector<ElementId>& seeds) {
  stamp_.resize(c.element_capacity(), 0);
  owner_.resize(c.element_capacity(), -1);
  if (++epoch_ == 0) {  // the stamps wrapped around: clear them
    std::fill(stamp_.begin(), stamp_.end(), 0);
    epoch_ = 1;
  }
  // One search per seed; `parent` joins searches that met (union-find), and the root of a
  // joined search owns the queue of the elements it has still to expand.
  const int n = static_cast<int>(seeds.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::vector<ElementId>> queue(n);
  std::vector<std::size_t> head(n, 0);
  auto find = [&](int s) {
    while (parent[s] != s) s = parent[s] = parent[parent[s]];
    return s;
  };
  auto pending = [&](int s) { return queue[s].size() - head[s]; };
  auto join = [&](int a, int b) {  // a, b roots; the longer queue absorbs the shorter
    if (pending(a) < pending(b)) std::swap(a, b);
    queue[a].insert(queue[a].end(), queue[b].begin() + static_cast<std::ptrdiff_t>(head[b]), queue[b].end());
    queue[b].clear();
    head[b] = 0;
    parent[b] = a;
    return a;
  };
  int roots = n;
  for (int s = 0; s < n; ++s) {
    stamp_[seeds[s]] = epoch_;
    owner_[seeds[s]] = s;
    queue[s].push_back(seeds[s]);
  }
  std::vector<int> live(n);
  std::iota(live.begin(), live.end(), 0);
  std::size_t visited = n;
  // Expand the searches in turn, one element each, until at most one can still grow: then
  // every other search has either met it or enclosed a whole part by itself.
  while (live.size() > 1) {
    for (int s : live) {
      int r = find(s);
      if (r != s || pending(r) == 0) continue;
      const ElementId e = queue[r][head[r]++];
      for (int j = 0; j <= c.dim(); ++j) {
        const ElementId next = c.neighbor(e, j);
        if (next == no_id) continue;
        if (stamp_[next] != epoch_) {
          stamp_[next] = epoch_;
          owner_[next] = r;
          queue[r].push_back(next);
          ++visited;
        } else if (const int other = find(owner_[next]); other != r) {
          r = join(r, other);
          --roots;
        }
      }
    }
    std::erase_if(live, [&](int s) { return find(s) != s || pending(s) == 0; });
  }
  last_search_size_ += visited;
  return roots > 1;
}

}  // namespace snede
