#include "topology/rank_refinement.hpp"

#include <algorithm>
#include <initializer_list>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

#include "core/log_event.hpp"
#include "core/rank_agreement.hpp"
#include "core/rank_messages.hpp"
#include "mesh/vertex_parents.hpp"
#include "topology/bisection.hpp"
#include "topology/refine_around.hpp"
#include "topology/refine_near_segment.hpp"

namespace snede {
namespace {

std::int64_t sum_over_ranks(MPI_Comm comm, std::int64_t value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_INT64_T, MPI_SUM, comm);
  return value;
}

// Appends `items` to the message for rank r.
void append(std::vector<std::vector<std::int64_t>>& messages, std::int64_t r, std::initializer_list<std::int64_t> items) {
  auto& message = messages[static_cast<std::size_t>(r)];
  message.insert(message.end(), items);
}

// Item i's question (`width` numbers, written by question(i, out)) asked of rank whom[i], and
// the reply answer(question, out) appends there (`reply_width` values of `type`), back in item
// order (collective).
template <class T, class Question, class Answer>
std::vector<T> ask_ranks(MPI_Comm comm, const std::vector<int>& whom, std::size_t width, Question question,
                         std::size_t reply_width, MPI_Datatype type, Answer answer) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::vector<std::vector<std::int64_t>> asked(static_cast<std::size_t>(size));
  for (std::size_t i = 0; i < whom.size(); ++i) {
    auto& message = asked[static_cast<std::size_t>(whom[i])];
    question(i, message);
    message.push_back(rank);  // where the reply goes
  }
  const std::vector<std::int64_t> questions = exchange_messages(comm, asked, MPI_INT64_T);
  std::vector<std::vector<T>> replies(static_cast<std::size_t>(size));
  for (std::size_t at = 0; at < questions.size(); at += width + 1)
    answer(std::span<const std::int64_t>(questions.data() + at, width), replies[static_cast<std::size_t>(questions[at + width])]);
  const std::vector<T> got = exchange_messages(comm, replies, type);
  // The replies come by the rank that answered, each rank's in the order it was asked.
  std::vector<std::size_t> next(static_cast<std::size_t>(size) + 1, 0);
  for (int r : whom) next[static_cast<std::size_t>(r) + 1] += reply_width;
  for (std::size_t r = 0; r < static_cast<std::size_t>(size); ++r) next[r + 1] += next[r];
  std::vector<T> out(whom.size() * reply_width);
  for (std::size_t i = 0; i < whom.size(); ++i) {
    std::size_t& from = next[static_cast<std::size_t>(whom[i])];
    std::copy_n(got.begin() + static_cast<std::ptrdiff_t>(from), reply_width, out.begin() + static_cast<std::ptrdiff_t>(i * reply_width));
    from += reply_width;
  }
  return out;
}

struct EdgeKeyHash {
  std::size_t operator()(const std::pair<std::int64_t, std::int64_t>& edge) const {
    return std::hash<std::int64_t>()(edge.first * 2654435761LL ^ edge.second);
  }
};

// The vertices a rank shares with others, which ranks may hold each, and the live elements
// around each: a watcher (§7.4) follows every split. A midpoint may be held by the ranks that
// hold both its parents (a superset: a rank may hold both ends of an edge and not the edge).
class RankBoundary final : public ConnectivityWatcher, public EdgeRings {
 public:
  RankBoundary(Mesh& mesh, std::unordered_map<VertexId, std::vector<int>> holders)
      : mesh_(mesh), holders_(std::move(holders)) {
    mesh_.connectivity().add_watcher(this, WatchMode::each_operation);
  }
  ~RankBoundary() override { mesh_.connectivity().remove_watcher(this); }
  RankBoundary(const RankBoundary&) = delete;
  RankBoundary& operator=(const RankBoundary&) = delete;

  // The other ranks that may hold v; nullptr when no other rank does.
  const std::vector<int>* other_holders(VertexId v) const {
    const auto it = holders_.find(v);
    return it == holders_.end() ? nullptr : &it->second;
  }

  std::vector<ElementId> around(VertexId a, VertexId b) const override {
    std::vector<ElementId> found;
    const auto star = stars_.find(a);
    if (!holders_.count(a) || !holders_.count(b) || star == stars_.end()) return found;
    for (ElementId e : star->second)
      if (mesh_.connectivity().element(e).simplex.contains(b)) found.push_back(e);
    return found;
  }

  void init(const Connectivity& c) override {
    stars_.clear();
    for (ElementId e : c.element_ids()) add(e, c.element(e).simplex);
  }

  void on_change(const Connectivity& c, const ConnectivityChange& change) override {
    for (const VertexEvent& event : change.vertex_events) {
      if (event.kind != VertexEventKind::added || event.parents.count() != 2) continue;
      const auto a = holders_.find(event.parents.vertex[0]), b = holders_.find(event.parents.vertex[1]);
      if (a == holders_.end() || b == holders_.end()) continue;
      std::vector<int> both;
      std::set_intersection(a->second.begin(), a->second.end(), b->second.begin(), b->second.end(),
                            std::back_inserter(both));
      if (!both.empty()) holders_[event.vertex] = std::move(both);
    }
    for (const auto& [e, simplex] : change.removed_elements) remove(e, simplex);
    for (const auto& [e, before] : change.changed_elements) {
      remove(e, before);
      add(e, c.element(e).simplex);
    }
    for (ElementId e : change.added_elements) add(e, c.element(e).simplex);
  }

 private:
  void add(ElementId e, const Simplex& s) {
    for (VertexId v : s.vertices())
      if (holders_.count(v)) stars_[v].push_back(e);
  }
  void remove(ElementId e, const Simplex& s) {
    for (VertexId v : s.vertices()) {
      const auto it = stars_.find(v);
      if (it != stars_.end()) it->second.erase(std::remove(it->second.begin(), it->second.end(), e), it->second.end());
    }
  }

  Mesh& mesh_;
  std::unordered_map<VertexId, std::vector<int>> holders_;  // sorted rank lists
  std::unordered_map<VertexId, std::vector<ElementId>> stars_;
};

// For every vertex this rank holds that others hold too (by local id), the other ranks. Each
// global id is asked about at rank (id mod size), which answers every holder.
std::unordered_map<VertexId, std::vector<int>> shared_vertices(MPI_Comm comm, const std::vector<std::int64_t>& gid) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::vector<std::vector<std::int64_t>> asked(static_cast<std::size_t>(size));
  for (std::int64_t g : gid) append(asked, g % size, {g, rank});
  std::vector<std::int64_t> held = exchange_messages(comm, asked, MPI_INT64_T);
  std::vector<std::pair<std::int64_t, std::int64_t>> by_id;  // (global id, holder)
  for (std::size_t i = 0; i < held.size(); i += 2) by_id.emplace_back(held[i], held[i + 1]);
  std::sort(by_id.begin(), by_id.end());
  std::vector<std::vector<std::int64_t>> answers(static_cast<std::size_t>(size));  // id, k, k ranks
  for (std::size_t first = 0, last = 0; first < by_id.size(); first = last) {
    while (last < by_id.size() && by_id[last].first == by_id[first].first) ++last;
    if (last - first < 2) continue;
    for (std::size_t i = first; i < last; ++i) {
      append(answers, by_id[i].second, {by_id[i].first, static_cast<std::int64_t>(last - first - 1)});
      for (std::size_t j = first; j < last; ++j)
        if (j != i) append(answers, by_id[i].second, {by_id[j].second});
    }
  }
  const std::vector<std::int64_t> told = exchange_messages(comm, answers, MPI_INT64_T);
  std::unordered_map<std::int64_t, VertexId> local_of;
  for (std::size_t v = 0; v < gid.size(); ++v) local_of.emplace(gid[v], static_cast<VertexId>(v));
  std::unordered_map<VertexId, std::vector<int>> holders;
  for (std::size_t i = 0; i < told.size();) {
    const std::int64_t id = told[i], k = told[i + 1];
    std::vector<int>& others = holders[local_of.at(id)];
    for (std::int64_t j = 0; j < k; ++j) others.push_back(static_cast<int>(told[i + 2 + static_cast<std::size_t>(j)]));
    std::sort(others.begin(), others.end());
    i += 2 + static_cast<std::size_t>(k);
  }
  return holders;
}

// The part copied with its vertices in the order of their global ids, so that the labelling's
// ties between equal edges (vertex ids: initial_labelling.hpp) break as in the serial mesh;
// `original` gives each vertex's index in the part given.
DistributedMesh sorted_part(const DistributedMesh& part, std::vector<std::int64_t>& original) {
  const Mesh& local = *part.local;
  const auto n = static_cast<std::size_t>(local.n_points());
  original.resize(n);
  std::iota(original.begin(), original.end(), std::int64_t{0});
  std::sort(original.begin(), original.end(),
            [&](std::int64_t a, std::int64_t b) { return part.global_vertex[static_cast<std::size_t>(a)] < part.global_vertex[static_cast<std::size_t>(b)]; });
  std::vector<std::int64_t> sorted_of(n), cells;
  DistributedMesh out{.comm = part.comm, .local = nullptr, .global_vertex = {}, .owned = {}, .global_number = {},
                      .n_global_vertices = part.n_global_vertices, .n_global_cells = part.n_global_cells};
  std::vector<double> points;
  const auto d = static_cast<std::size_t>(local.space_dim());
  for (std::size_t i = 0; i < n; ++i) {
    const auto from = static_cast<std::size_t>(original[i]);
    sorted_of[from] = static_cast<std::int64_t>(i);
    out.global_vertex.push_back(part.global_vertex[from]);
    out.owned.push_back(part.owned[from]);
    out.global_number.push_back(part.global_number[from]);
    points.insert(points.end(), local.points().begin() + static_cast<std::ptrdiff_t>(from * d),
                  local.points().begin() + static_cast<std::ptrdiff_t>((from + 1) * d));
  }
  for (VertexId v : local.cells()) cells.push_back(sorted_of[static_cast<std::size_t>(v)]);
  out.local = std::make_unique<Mesh>(local.cell_dim(), local.space_dim(), std::move(points), cells);
  return out;
}

// The rule the whole mesh would choose (initial_labelling.hpp): newest-vertex only when every
// rank's cells allow it.
BisectionRule agreed_rule(MPI_Comm comm, const Mesh& mesh) {
  int longest = bisection_rule_for(mesh) == BisectionRule::longest_edge;
  MPI_Allreduce(MPI_IN_PLACE, &longest, 1, MPI_INT, MPI_MAX, comm);
  return longest ? BisectionRule::longest_edge : BisectionRule::newest_vertex;
}

}  // namespace

// One rank's share of a distributed refinement, kept between edits: its part (cells, vertices,
// owners, numbering) refined in place, the bisection hierarchy and the rank boundary, and the
// exchanges that number the new vertices and close each refinement across the rank boundary.
class PartRefinement::State {
 public:
  State(const DistributedMesh& part, const PartLabels* labels)
      : comm_(part.comm), part_(sorted_part(part, original_)), mesh_(*part_.local) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
    for (std::size_t v = 0; v < gid().size(); ++v) local_of_.emplace(gid()[v], static_cast<VertexId>(v));
    boundary_.emplace(mesh_, shared_vertices(comm_, gid()));
    std::vector<TaggedSimplex> roots;
    std::string problem = labels ? root_labels(*labels, roots) : "";
    if (problem = first_rank_problem(comm_, "PartRefinement", problem); !problem.empty()) throw std::invalid_argument(problem);
    bisection_.emplace(mesh_, labels ? labels->rule : agreed_rule(comm_, mesh_), std::move(roots));
    bisection_->set_edge_rings(&*boundary_);
  }
  ~State() {
    bisection_.reset();  // they watch the mesh
    boundary_.reset();
  }

  DistributedMesh& part() { return part_; }
  const std::vector<std::int64_t>& original() const { return original_; }
  bool spent() const { return spent_; }
  Bisection& bisection() { return *bisection_; }

  // Starts an edit: `field` (width per vertex of the part) is carried to the new vertices.
  void begin(std::span<const double> field, int width) {
    if (spent_) throw std::logic_error("PartRefinement: its part was rebalanced; refine the rebalanced part");
    const auto n = static_cast<std::size_t>(mesh_.n_points());
    if (width < 1 || field.size() != n * static_cast<std::size_t>(width))
      throw std::invalid_argument("PartRefinement: the field holds " + std::to_string(field.size()) + " values, not " +
                                  std::to_string(width) + " per each of the part's " + std::to_string(n) + " vertices");
    field_.assign(field.begin(), field.end());
    width_ = width;
    n_before_ = n_numbered_ = n_told_ = mesh_.n_points();
    n_global_ = part_.n_global_vertices;
    numbered_.clear();
    judged_.clear();
    waiting_.clear();
  }

  // After this rank's own splits: numbers the new vertices and splits the edges other ranks
  // split, until no rank splits any more (collective). Returns the cells split here.
  std::int64_t close_across_ranks() {
    const ScopedEvent timed(log_event("SnedeRankAgreeSplits"));
    std::int64_t split = 0;
    for (;;) {
      number_new_vertices();
      std::vector<std::vector<std::int64_t>> told(static_cast<std::size_t>(size_));
      for (VertexId v = n_told_; v < mesh_.n_points(); ++v)
        if (const std::vector<int>* others = boundary_->other_holders(v)) {
          const VertexParents parents = mesh_.parents(v);
          for (int r : *others)
            append(told, r, {gid()[static_cast<std::size_t>(parents.vertex[0])], gid()[static_cast<std::size_t>(parents.vertex[1])]});
        }
      n_told_ = mesh_.n_points();
      // An edge told of may end at a midpoint this rank made in the same round and has not
      // numbered yet: it waits for the next round's numbers.
      std::vector<std::int64_t> split_elsewhere = exchange_messages(comm_, told, MPI_INT64_T);
      split_elsewhere.insert(split_elsewhere.end(), waiting_.begin(), waiting_.end());
      waiting_.clear();
      std::int64_t made = 0;
      for (std::size_t i = 0; i < split_elsewhere.size(); i += 2) {
        const auto a = local_of_.find(split_elsewhere[i]), b = local_of_.find(split_elsewhere[i + 1]);
        if (a == local_of_.end() || b == local_of_.end()) {
          waiting_.insert(waiting_.end(), {split_elsewhere[i], split_elsewhere[i + 1]});
          continue;
        }
        // Split the elements around the edge at their refinement edges until it is split.
        for (std::vector<ElementId> ring = boundary_->around(a->second, b->second); !ring.empty();
             ring = boundary_->around(a->second, b->second))
          made += static_cast<std::int64_t>(bisection_->bisect(ring.front()));
      }
      split += made;
      if (sum_over_ranks(comm_, made) == 0) return split;
    }
  }

  // Ends the edit (collective): balanced parts (as distribute_cells judges them) stay refined in
  // place, renumbered; others go to DMPlex to be balanced, and this refinement is spent.
  RankRefinementReport finish(std::int64_t n_split) {
    const ScopedEvent timed(log_event("SnedeRankNewPart"));
    interpolate_field();
    std::int64_t n_cells = static_cast<std::int64_t>(mesh_.n_cells()), largest = n_cells;
    MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_INT64_T, MPI_MAX, comm_);
    const std::int64_t total = sum_over_ranks(comm_, n_cells);
    if (static_cast<double>(largest) * size_ <= 1.2 * static_cast<double>(total)) {
      renumber_in_place(total);
      return RankRefinementReport{.field = std::move(field_), .new_vertices = std::move(judged_), .n_split = n_split,
                                  .rebalanced = std::nullopt, .labels = {}};
    }
    spent_ = true;
    return rebalanced_part(n_split);
  }

 private:
  RankRefinementReport rebalanced_part(std::int64_t n_split) {
    RankCells given{.cell_dim = mesh_.cell_dim(), .space_dim = mesh_.space_dim(), .cells = {}, .coordinates = {}};
    for (VertexId v : mesh_.cells()) given.cells.push_back(gid()[static_cast<std::size_t>(v)]);
    // Each rank takes the coordinates and field of one range of global ids.
    const auto d = static_cast<std::size_t>(mesh_.space_dim()), w = static_cast<std::size_t>(width_);
    std::vector<std::vector<std::int64_t>> ids(static_cast<std::size_t>(size_));
    std::vector<std::vector<double>> values(static_cast<std::size_t>(size_));
    for (VertexId v = 0; v < mesh_.n_points(); ++v) {
      const auto r = static_cast<std::size_t>(range_holder(gid()[v]));
      ids[r].push_back(gid()[v]);
      values[r].insert(values[r].end(), mesh_.point(v).begin(), mesh_.point(v).end());
      values[r].insert(values[r].end(), field_.begin() + static_cast<std::ptrdiff_t>(v * w),
                       field_.begin() + static_cast<std::ptrdiff_t>((v + 1) * w));
    }
    const std::vector<std::int64_t> got_ids = exchange_messages(comm_, ids, MPI_INT64_T);
    const std::vector<double> got_values = exchange_messages(comm_, values, MPI_DOUBLE);
    const std::int64_t start = range_start(rank_), n_range = range_start(rank_ + 1) - start;
    given.coordinates.assign(static_cast<std::size_t>(n_range) * d, 0.0);
    std::vector<double> range_field(static_cast<std::size_t>(n_range) * w, 0.0);
    for (std::size_t i = 0; i < got_ids.size(); ++i) {  // a vertex several ranks hold comes alike from each
      const auto at = static_cast<std::size_t>(got_ids[i] - start);
      std::copy_n(got_values.begin() + static_cast<std::ptrdiff_t>(i * (d + w)), d, given.coordinates.begin() + static_cast<std::ptrdiff_t>(at * d));
      std::copy_n(got_values.begin() + static_cast<std::ptrdiff_t>(i * (d + w) + d), w, range_field.begin() + static_cast<std::ptrdiff_t>(at * w));
    }
    const std::vector<std::int64_t> labels = labels_of_cells();
    const BisectionRule rule = bisection_->hierarchy().rule();
    RankRefinementReport out{.field = {}, .new_vertices = std::move(judged_), .n_split = n_split,
                             .rebalanced = distribute_cells(comm_, std::move(given)), .labels = {}};
    const DistributedMesh& balanced = *out.rebalanced;
    out.field = field_from_ranges(balanced.global_vertex, range_field, start);
    std::vector<std::int64_t> cells;
    for (VertexId v : balanced.local->cells()) cells.push_back(balanced.global_vertex[static_cast<std::size_t>(v)]);
    out.labels = PartLabels{.rule = rule, .cells = labels_after_rebalancing(labels, cells)};
    return out;
  }

  // The part refined in place: owners for the new vertices that other ranks hold too (the
  // lowest rank holding one), and PETSc's vertex numbering anew (owned vertices contiguous in
  // rank order), both agreed by global id at rank (id mod size).
  void renumber_in_place(std::int64_t n_global_cells) {
    const VertexId n = mesh_.n_points();
    part_.owned.resize(static_cast<std::size_t>(n), 1);
    std::vector<VertexId> shared;  // vertices other ranks may hold
    for (VertexId v = 0; v < n; ++v)
      if (boundary_->other_holders(v)) shared.push_back(v);
    // The owner of each shared new vertex.
    std::vector<std::vector<std::int64_t>> asked(static_cast<std::size_t>(size_));
    for (VertexId v : shared)
      if (v >= n_before_) append(asked, gid()[static_cast<std::size_t>(v)] % size_, {gid()[static_cast<std::size_t>(v)], rank_});
    const std::vector<std::int64_t> holders = exchange_messages(comm_, asked, MPI_INT64_T);
    std::unordered_map<std::int64_t, std::int64_t> owner;
    for (std::size_t i = 0; i < holders.size(); i += 2) {
      const auto [at, fresh] = owner.emplace(holders[i], holders[i + 1]);
      if (!fresh) at->second = std::min(at->second, holders[i + 1]);
    }
    std::vector<std::vector<std::int64_t>> told(static_cast<std::size_t>(size_));
    for (std::size_t i = 0; i < holders.size(); i += 2) append(told, holders[i + 1], {holders[i], owner.at(holders[i])});
    const std::vector<std::int64_t> owners = exchange_messages(comm_, told, MPI_INT64_T);
    for (std::size_t i = 0; i < owners.size(); i += 2)
      part_.owned[static_cast<std::size_t>(local_of_.at(owners[i]))] = owners[i + 1] == rank_;
    // PETSc's numbering: this rank's owned vertices after the lower ranks'.
    std::int64_t first = 0, n_owned = std::count(part_.owned.begin(), part_.owned.end(), std::uint8_t{1});
    MPI_Exscan(&n_owned, &first, 1, MPI_INT64_T, MPI_SUM, comm_);
    if (rank_ == 0) first = 0;
    std::vector<std::int64_t> number(static_cast<std::size_t>(n), -1);
    for (std::size_t v = 0; v < number.size(); ++v)
      if (part_.owned[v]) number[v] = first++;
    // A ghost learns its owner's number.
    std::vector<std::vector<std::int64_t>> given(static_cast<std::size_t>(size_));
    for (VertexId v : shared) {
      const std::int64_t id = gid()[static_cast<std::size_t>(v)];
      append(given, id % size_, {id, rank_, number[static_cast<std::size_t>(v)]});
    }
    const std::vector<std::int64_t> numbers = exchange_messages(comm_, given, MPI_INT64_T);
    std::unordered_map<std::int64_t, std::int64_t> owners_number;
    for (std::size_t i = 0; i < numbers.size(); i += 3)
      if (numbers[i + 2] >= 0) owners_number.emplace(numbers[i], numbers[i + 2]);
    std::vector<std::vector<std::int64_t>> answers(static_cast<std::size_t>(size_));
    for (std::size_t i = 0; i < numbers.size(); i += 3)
      if (numbers[i + 2] < 0) append(answers, numbers[i + 1], {numbers[i], owners_number.at(numbers[i])});
    const std::vector<std::int64_t> ghost_numbers = exchange_messages(comm_, answers, MPI_INT64_T);
    for (std::size_t i = 0; i < ghost_numbers.size(); i += 2)
      number[static_cast<std::size_t>(local_of_.at(ghost_numbers[i]))] = ghost_numbers[i + 1];
    part_.global_number = std::move(number);
    part_.n_global_vertices = n_global_;
    part_.n_global_cells = n_global_cells;
  }


  // Global ids for the new vertices: a midpoint is named by its parents' ids and numbered by
  // rank (smaller parent id mod size), so every rank that splits an edge gives its midpoint the
  // same id. Midpoints of midpoints wait for their parents' ids (collective rounds).
  void number_new_vertices() {
    gid().resize(static_cast<std::size_t>(mesh_.n_points()), -1);
    for (;;) {
      std::vector<std::vector<std::int64_t>> asked(static_cast<std::size_t>(size_));
      std::int64_t waiting = 0;
      for (VertexId v = n_numbered_; v < mesh_.n_points(); ++v) {
        if (gid()[v] >= 0) continue;
        const VertexParents parents = mesh_.parents(v);
        const std::int64_t a = gid()[parents.vertex[0]], b = gid()[parents.vertex[1]];
        if (a < 0 || b < 0) {
          ++waiting;
          continue;
        }
        const auto [low, high] = std::minmax(a, b);
        append(asked, low % size_, {low, high, v, rank_});
      }
      std::int64_t asking = 0;
      for (const auto& list : asked) asking += static_cast<std::int64_t>(list.size());
      if (sum_over_ranks(comm_, asking + waiting) == 0) break;
      const std::vector<std::int64_t> questions = exchange_messages(comm_, asked, MPI_INT64_T);
      std::vector<std::pair<std::int64_t, std::int64_t>> fresh;  // edges numbered in this round, in order
      for (std::size_t i = 0; i < questions.size(); i += 4)
        if (numbered_.emplace(std::make_pair(questions[i], questions[i + 1]), -1).second)
          fresh.emplace_back(questions[i], questions[i + 1]);
      std::int64_t first = 0, n_fresh = static_cast<std::int64_t>(fresh.size());
      MPI_Exscan(&n_fresh, &first, 1, MPI_INT64_T, MPI_SUM, comm_);
      if (rank_ == 0) first = 0;
      for (std::size_t k = 0; k < fresh.size(); ++k) {
        const std::int64_t id = n_global_ + first + static_cast<std::int64_t>(k);
        numbered_[fresh[k]] = id;
        judged_.insert(judged_.end(), {id, fresh[k].first, fresh[k].second});
      }
      n_global_ += sum_over_ranks(comm_, n_fresh);
      std::vector<std::vector<std::int64_t>> answers(static_cast<std::size_t>(size_));
      for (std::size_t i = 0; i < questions.size(); i += 4)
        append(answers, questions[i + 3], {questions[i + 2], numbered_.at({questions[i], questions[i + 1]})});
      const std::vector<std::int64_t> ids = exchange_messages(comm_, answers, MPI_INT64_T);
      for (std::size_t i = 0; i < ids.size(); i += 2) {
        gid()[static_cast<std::size_t>(ids[i])] = ids[i + 1];
        local_of_.emplace(ids[i + 1], static_cast<VertexId>(ids[i]));
      }
      while (n_numbered_ < mesh_.n_points() && gid()[n_numbered_] >= 0) ++n_numbered_;
    }
  }

  // New vertices' values from their parents', in the order they were made (parents first).
  void interpolate_field() {
    std::vector<VertexEvent> added;
    for (VertexId v = n_before_; v < mesh_.n_points(); ++v) added.push_back({VertexEventKind::added, v, mesh_.parents(v)});
    field_.resize(static_cast<std::size_t>(mesh_.n_points()) * static_cast<std::size_t>(width_), 0.0);
    replay_vertex_events(field_, width_, added);  // as a serial Body's fields follow (§7.4)
  }

  std::int64_t range_start(int r) const { return n_global_ * r / size_; }
  int range_holder(std::int64_t id) const {
    int r = static_cast<int>(id * size_ / std::max<std::int64_t>(n_global_, 1));
    while (r > 0 && id < range_start(r)) --r;
    while (r + 1 < size_ && id >= range_start(r + 1)) ++r;
    return r;
  }

  // The field at each of `ids`, asked of the ranks holding their ranges (collective).
  std::vector<double> field_from_ranges(const std::vector<std::int64_t>& ids, const std::vector<double>& range_field,
                                        std::int64_t start) const {
    const auto w = static_cast<std::size_t>(width_);
    std::vector<int> whom;
    for (std::int64_t id : ids) whom.push_back(range_holder(id));
    return ask_ranks<double>(
        comm_, whom, 1, [&](std::size_t i, std::vector<std::int64_t>& out) { out.push_back(ids[i]); }, w, MPI_DOUBLE,
        [&](std::span<const std::int64_t> id, std::vector<double>& out) {
          const auto at = static_cast<std::ptrdiff_t>(static_cast<std::size_t>(id[0] - start) * w);
          out.insert(out.end(), range_field.begin() + at, range_field.begin() + at + static_cast<std::ptrdiff_t>(w));
        });
  }

  // The labels of the cells a rebalancing gave this rank (`cells`: its new part's, by global
  // ids), from the ranks that had them: each cell is filed at rank (smallest id mod size) under
  // its sorted ids (collective).
  std::vector<std::int64_t> labels_after_rebalancing(const std::vector<std::int64_t>& labels,
                                                     const std::vector<std::int64_t>& cells) const {
    const auto corners = static_cast<std::size_t>(mesh_.cell_dim() + 1), width = corners + 1;
    const auto key_of = [&](const std::int64_t* ids) {
      std::vector<std::int64_t> key(ids, ids + corners);
      std::sort(key.begin(), key.end());
      return key;
    };
    std::vector<std::vector<std::int64_t>> filed(static_cast<std::size_t>(size_));
    for (std::size_t at = 0; at < labels.size(); at += width) {
      const std::vector<std::int64_t> key = key_of(labels.data() + at);
      auto& message = filed[static_cast<std::size_t>(key[0] % size_)];
      message.insert(message.end(), key.begin(), key.end());
      message.insert(message.end(), labels.begin() + static_cast<std::ptrdiff_t>(at),
                     labels.begin() + static_cast<std::ptrdiff_t>(at + width));
    }
    const std::vector<std::int64_t> kept = exchange_messages(comm_, filed, MPI_INT64_T);
    std::map<std::vector<std::int64_t>, std::size_t> at_key;  // where each filed label starts in `kept`
    for (std::size_t at = 0; at < kept.size(); at += corners + width)
      at_key.emplace(std::vector<std::int64_t>(kept.begin() + static_cast<std::ptrdiff_t>(at),
                                               kept.begin() + static_cast<std::ptrdiff_t>(at + corners)),
                     at + corners);
    std::vector<int> whom;
    std::vector<std::vector<std::int64_t>> keys;
    for (std::size_t at = 0; at < cells.size(); at += corners) {
      keys.push_back(key_of(cells.data() + at));
      whom.push_back(static_cast<int>(keys.back()[0] % size_));
    }
    return ask_ranks<std::int64_t>(
        comm_, whom, corners,
        [&](std::size_t i, std::vector<std::int64_t>& out) { out.insert(out.end(), keys[i].begin(), keys[i].end()); },
        width, MPI_INT64_T, [&](std::span<const std::int64_t> key, std::vector<std::int64_t>& out) {
          const std::size_t at = at_key.at(std::vector<std::int64_t>(key.begin(), key.end()));
          out.insert(out.end(), kept.begin() + static_cast<std::ptrdiff_t>(at),
                     kept.begin() + static_cast<std::ptrdiff_t>(at + width));
        });
  }

  // The given labels as the sorted copy's roots, one per element (its row); what is wrong
  // with them, or empty.
  std::string root_labels(const PartLabels& labels, std::vector<TaggedSimplex>& roots) const {
    const int d = mesh_.cell_dim();
    const auto width = static_cast<std::size_t>(d + 2);
    if (labels.cells.size() != mesh_.n_cells() * width)
      return "the labels hold " + std::to_string(labels.cells.size()) + " numbers for " +
             std::to_string(mesh_.n_cells()) + " cells (" + std::to_string(width) + " each): not this part's";
    for (std::size_t e = 0; e < mesh_.n_cells(); ++e) {
      TaggedSimplex label;
      label.dim = static_cast<std::int8_t>(d);
      label.tag = static_cast<std::int8_t>(labels.cells[e * width + static_cast<std::size_t>(d) + 1]);
      for (int i = 0; i <= d; ++i) {
        const auto at = local_of_.find(labels.cells[e * width + static_cast<std::size_t>(i)]);
        if (at == local_of_.end() || !mesh_.connectivity().element(static_cast<ElementId>(e)).simplex.contains(at->second))
          return "the label of cell " + std::to_string(e) + " names other vertices than the cell's: not this part's";
        label.vertex[static_cast<std::size_t>(i)] = at->second;
      }
      if (label.tag < 1 || label.tag > d) return "the label of cell " + std::to_string(e) + " has tag " + std::to_string(label.tag);
      roots.push_back(label);
    }
    return "";
  }

  // The live cells' labels by global ids, in the mesh's cell order (Mesh::cells).
  std::vector<std::int64_t> labels_of_cells() const {
    std::vector<std::int64_t> out;
    const int d = mesh_.cell_dim();
    for (ElementId e : mesh_.connectivity().element_ids()) {
      const TaggedSimplex& label = bisection_->hierarchy().label(e);
      for (int i = 0; i <= d; ++i) out.push_back(gid()[static_cast<std::size_t>(label.vertex[static_cast<std::size_t>(i)])]);
      out.push_back(label.tag);
    }
    return out;
  }

  std::vector<std::int64_t>& gid() { return part_.global_vertex; }
  const std::vector<std::int64_t>& gid() const { return part_.global_vertex; }

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  std::vector<std::int64_t> original_;  // the index in the given part of each vertex it had
  DistributedMesh part_;
  Mesh& mesh_;
  std::vector<double> field_;
  int width_ = 1;
  std::int64_t n_global_ = 0;  // vertices numbered so far in this edit
  std::unordered_map<std::int64_t, VertexId> local_of_;
  // As the numbering rank: the edges whose midpoints this rank numbered, and the triples.
  std::unordered_map<std::pair<std::int64_t, std::int64_t>, std::int64_t, EdgeKeyHash> numbered_;
  std::vector<std::int64_t> judged_;
  std::vector<std::int64_t> waiting_;  // edges told of, by global ids, with an end not (yet) here
  VertexId n_numbered_ = 0, n_told_ = 0, n_before_ = 0;
  bool spent_ = false;
  std::optional<RankBoundary> boundary_;
  std::optional<Bisection> bisection_;
};

namespace {

std::string point_text(std::span<const double> x) {
  std::string text;
  for (double c : x) text += (text.empty() ? "" : ", ") + std::to_string(c);
  return "(" + text + ")";
}

}  // namespace

PartRefinement::PartRefinement(const DistributedMesh& part, const PartLabels* labels)
    : state_(std::make_unique<State>(part, labels)) {}

PartRefinement::~PartRefinement() = default;

const DistributedMesh& PartRefinement::part() const { return state_->part(); }
DistributedMesh& PartRefinement::part() { return state_->part(); }
const std::vector<std::int64_t>& PartRefinement::original_vertex() const { return state_->original(); }
bool PartRefinement::spent() const { return state_->spent(); }

RankRefinementReport PartRefinement::refine_uniform(int levels, std::span<const double> field, int width) {
  if (levels < 0) throw std::invalid_argument("refine_uniform: levels must be ≥ 0, got " + std::to_string(levels));
  state_->begin(field, width);
  std::int64_t split = 0;
  for (int level = 0; level < levels; ++level) {
    {
      const ScopedEvent timed(log_event("SnedeRankBisect"));
      split += static_cast<std::int64_t>(state_->bisection().refine_uniform(1));
    }
    split += state_->close_across_ranks();
  }
  return state_->finish(sum_over_ranks(state_->part().comm, split));
}

template <class Mark>
RankRefinementReport PartRefinement::refine_until_unmarked(std::span<const double> field, int width,
                                                           const std::string& caller, Mark mark) {
  state_->begin(field, width);
  const MPI_Comm comm = state_->part().comm;
  std::int64_t split = 0;
  for (bool first = true;; first = false) {
    std::int64_t marked = 0;
    std::string problem;
    try {
      const ScopedEvent timed(log_event("SnedeRankBisect"));
      marked = static_cast<std::int64_t>(mark(state_->bisection(), first));
    } catch (const std::invalid_argument& error) {
      problem = error.what();
    }
    if (problem = first_rank_problem(comm, caller, problem); !problem.empty()) throw std::invalid_argument(problem);
    split += marked + state_->close_across_ranks();
    if (sum_over_ranks(comm, marked) == 0) break;
  }
  return state_->finish(sum_over_ranks(comm, split));
}

RankRefinementReport PartRefinement::refine_around(std::span<const double> x, double h, std::span<const double> field,
                                                   int width) {
  const DistributedMesh& part = state_->part();
  if (x.size() != static_cast<std::size_t>(part.local->space_dim()))
    throw std::invalid_argument("refine_around: the point has " + std::to_string(x.size()) + " coordinates, the mesh is " +
                                std::to_string(part.local->space_dim()) + "-D");
  bool holds_x = false;
  return refine_until_unmarked(field, width, "refine_around", [&](Bisection& bisection, bool first) {
    if (first) {
      holds_x = !bisection.hierarchy().roots_containing(x).empty();
      if (sum_over_ranks(part.comm, holds_x ? 1 : 0) == 0)
        throw std::invalid_argument("point " + point_text(x) + " is outside the mesh (no rank's cells hold it)");
    }
    return holds_x ? snede::refine_around(bisection, x, h) : std::size_t{0};
  });
}

RankRefinementReport PartRefinement::refine_near_segment(std::span<const double> a, std::span<const double> b, double h,
                                                         double radius, std::span<const double> field, int width) {
  const MPI_Comm comm = state_->part().comm;
  return refine_until_unmarked(field, width, "refine_near_segment", [&](Bisection& bisection, bool first) {
    bool near_here = false;
    std::size_t split = 0;
    std::string problem;
    try {
      split = snede::refine_near_segment(bisection, a, b, h, radius, &near_here);
    } catch (const std::invalid_argument& error) {
      problem = error.what();  // thrown after the reduction below, which every rank enters
    }
    const bool near_anywhere = !first || sum_over_ranks(comm, near_here ? 1 : 0) > 0;
    if (!problem.empty()) throw std::invalid_argument(problem);
    if (!near_anywhere)
      throw std::invalid_argument("the segment does not come within radius " + std::to_string(radius) +
                                  " of the mesh (on no rank)");
    return split;
  });
}

}  // namespace snede
