#include "problem/rank_piece_holding.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "core/rank_messages.hpp"
#include "mesh/traversal.hpp"
#include "problem/piece_holding.hpp"
#include "problem/rigid_motion_gram.hpp"

namespace snede {
namespace {

int rank_of(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

int size_of(MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  return size;
}

int find_root(std::vector<int>& parent, int node) {
  while (parent[node] != node) node = parent[node] = parent[parent[node]];
  return node;
}

// Each of this rank's local pieces' label among the whole body's pieces, and how many there are.
std::pair<std::vector<int>, int> global_pieces(const DistributedMesh& part, const std::vector<int>& element_piece,
                                               int local_pieces) {
  const MPI_Comm comm = part.comm;
  const int rank = rank_of(comm), size = size_of(comm);
  const Connectivity& c = part.local->connectivity();
  const int corners = c.dim();  // a face's
  // Each boundary face of the rank's cells, to its judge: [sorted serial ids, rank, local piece].
  std::vector<std::vector<std::int64_t>> to_judge(size);
  std::array<std::int64_t, 3> key{};
  for (const auto& [simplex, face] : c.boundary()) {
    const auto vertices = simplex.vertices();
    for (int k = 0; k < corners; ++k) key[k] = part.global_vertex[vertices[k]];
    std::sort(key.begin(), key.begin() + corners);
    auto& message = to_judge[static_cast<std::size_t>(key[0] % size)];
    message.insert(message.end(), key.begin(), key.begin() + corners);
    message.push_back(rank);
    message.push_back(element_piece[c.face(face).element]);
  }
  const std::vector<std::int64_t> judged = exchange_messages(comm, to_judge, MPI_INT64_T);
  // A face given twice joins two ranks' pieces: [rank, piece, rank, piece] to rank 0.
  const std::size_t record = static_cast<std::size_t>(corners) + 2;
  std::vector<std::size_t> order(judged.size() / record);
  std::iota(order.begin(), order.end(), 0);
  auto face_of = [&](std::size_t k) {
    return std::vector<std::int64_t>(judged.begin() + static_cast<std::ptrdiff_t>(k * record),
                                     judged.begin() + static_cast<std::ptrdiff_t>(k * record + corners));
  };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return face_of(a) < face_of(b); });
  std::vector<std::vector<std::int64_t>> joins(size);
  for (std::size_t k = 0; k + 1 < order.size(); ++k)
    if (face_of(order[k]) == face_of(order[k + 1]))
      for (std::size_t side : {order[k], order[k + 1]})
        joins[0].insert(joins[0].end(), judged.begin() + static_cast<std::ptrdiff_t>(side * record + corners),
                        judged.begin() + static_cast<std::ptrdiff_t>(side * record + record));
  const std::vector<std::int64_t> all_joins = exchange_messages(comm, joins, MPI_INT64_T);
  // Rank 0 joins the pieces (nodes numbered rank by rank) and numbers the classes in that order.
  std::vector<int> counts(size), starts(size + 1, 0);
  MPI_Allgather(&local_pieces, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  std::partial_sum(counts.begin(), counts.end(), starts.begin() + 1);
  std::vector<int> labels(static_cast<std::size_t>(starts[size]));
  int n_pieces = 0;
  if (rank == 0) {
    std::vector<int> parent(labels.size());
    std::iota(parent.begin(), parent.end(), 0);
    for (std::size_t k = 0; k + 4 <= all_joins.size(); k += 4) {
      const int a = find_root(parent, starts[all_joins[k]] + static_cast<int>(all_joins[k + 1]));
      const int b = find_root(parent, starts[all_joins[k + 2]] + static_cast<int>(all_joins[k + 3]));
      parent[std::max(a, b)] = std::min(a, b);
    }
    std::vector<int> class_label(labels.size(), -1);
    for (std::size_t node = 0; node < labels.size(); ++node) {
      const int root = find_root(parent, static_cast<int>(node));
      if (class_label[root] < 0) class_label[root] = n_pieces++;
      labels[node] = class_label[root];
    }
  }
  MPI_Bcast(&n_pieces, 1, MPI_INT, 0, comm);
  std::vector<int> mine(static_cast<std::size_t>(local_pieces));
  MPI_Scatterv(labels.data(), counts.data(), starts.data(), MPI_INT, mine.data(), local_pieces, MPI_INT, 0, comm);
  return {mine, n_pieces};
}

}  // namespace

RankPieces pieces_on_ranks(const DistributedMesh& part, const Constraints& constraints) {
  const MPI_Comm comm = part.comm;
  const Mesh& mesh = *part.local;
  const Connectivity& c = mesh.connectivity();
  const int dim = mesh.dim();
  const auto [element_piece, local_pieces] = connected_components(c);
  const auto [global_of_local, n_pieces] = global_pieces(part, element_piece, local_pieces);
  // Each local vertex's pieces (a vertex where pieces meet without a face is in several).
  std::vector<std::pair<VertexId, int>> vertex_pieces;
  std::vector<std::int64_t> cells(static_cast<std::size_t>(n_pieces), 0);
  for (ElementId e : c.element_ids()) {
    const int piece = global_of_local[element_piece[e]];
    ++cells[piece];
    for (VertexId v : c.element(e).simplex.vertices()) vertex_pieces.emplace_back(v, piece);
  }
  std::sort(vertex_pieces.begin(), vertex_pieces.end());
  vertex_pieces.erase(std::unique(vertex_pieces.begin(), vertex_pieces.end()), vertex_pieces.end());
  // Each piece's origin: its constrained vertex of lowest serial id (coordinates from its owner),
  // and its lowest serial vertex id, for the message.
  constexpr std::int64_t none = std::numeric_limits<std::int64_t>::max();
  std::vector<std::int64_t> origin_vertex(static_cast<std::size_t>(n_pieces), none), some_vertex(origin_vertex);
  for (const auto& [v, piece] : vertex_pieces) {
    some_vertex[piece] = std::min(some_vertex[piece], part.global_vertex[v]);
    if (constraints.constrained_components(v) > 0)
      origin_vertex[piece] = std::min(origin_vertex[piece], part.global_vertex[v]);
  }
  MPI_Allreduce(MPI_IN_PLACE, origin_vertex.data(), n_pieces, MPI_INT64_T, MPI_MIN, comm);
  MPI_Allreduce(MPI_IN_PLACE, some_vertex.data(), n_pieces, MPI_INT64_T, MPI_MIN, comm);
  MPI_Allreduce(MPI_IN_PLACE, cells.data(), n_pieces, MPI_INT64_T, MPI_SUM, comm);
  std::vector<double> origins(static_cast<std::size_t>(n_pieces) * 3, 0.0);
  for (const auto& [v, piece] : vertex_pieces)
    if (part.owned[v] && part.global_vertex[v] == origin_vertex[piece])
      for (int k = 0; k < dim; ++k) origins[static_cast<std::size_t>(piece) * 3 + k] = mesh.point(v)[k];
  MPI_Allreduce(MPI_IN_PLACE, origins.data(), static_cast<int>(origins.size()), MPI_DOUBLE, MPI_SUM, comm);
  // Each piece's Gram on this rank (a ghost's rows too: a row given twice leaves the rank as it
  // is), its owned constrained components, summed over the ranks.
  std::vector<RigidMotionGram> grams(static_cast<std::size_t>(n_pieces), RigidMotionGram(dim));
  for (int piece = 0; piece < n_pieces; ++piece) {
    std::copy_n(origins.begin() + piece * 3, 3, grams[piece].origin.begin());
    grams[piece].has_origin = true;
  }
  std::vector<double> block(static_cast<std::size_t>(dim * dim));
  std::vector<std::int64_t> owned_components(static_cast<std::size_t>(n_pieces), 0);
  for (const auto& [v, piece] : vertex_pieces) {
    const std::size_t components = constraints.constrained_components(v);
    if (components == 0) continue;
    constraints.projection_block(v, block);
    grams[piece].add(mesh.point(v), block, components);
    if (part.owned[v]) owned_components[piece] += static_cast<std::int64_t>(components);
  }
  const int n_motions = dim == 3 ? 6 : 3;
  const std::size_t entries = static_cast<std::size_t>(n_motions * n_motions);
  std::vector<double> sums(static_cast<std::size_t>(n_pieces) * entries);
  for (int piece = 0; piece < n_pieces; ++piece) std::copy_n(grams[piece].gram.data(), entries, sums.data() + piece * entries);
  MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM, comm);
  std::vector<double> spans(static_cast<std::size_t>(n_pieces));
  for (int piece = 0; piece < n_pieces; ++piece) spans[piece] = grams[piece].span;
  MPI_Allreduce(MPI_IN_PLACE, spans.data(), n_pieces, MPI_DOUBLE, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, owned_components.data(), n_pieces, MPI_INT64_T, MPI_SUM, comm);
  RankPieces pieces{.cell_piece = {}, .n_pieces = n_pieces, .loose = {}, .lowest_vertex = some_vertex};
  for (ElementId e : c.element_ids()) pieces.cell_piece.push_back(global_of_local[element_piece[e]]);
  for (int piece = 0; piece < n_pieces; ++piece) {
    RigidMotionGram whole(dim);
    std::copy_n(sums.data() + piece * entries, entries, whole.gram.data());
    whole.span = spans[piece];
    whole.components = static_cast<std::size_t>(owned_components[piece]);
    const std::size_t stopped = whole.rank();
    if ((mesh.is_surface() ? whole.components : stopped) < static_cast<std::size_t>(n_motions))
      pieces.loose.push_back({piece, n_pieces, static_cast<std::size_t>(cells[piece]), no_id, whole.components, stopped,
                              static_cast<std::size_t>(n_motions)});
  }
  return pieces;
}

void require_held_on_ranks(const DistributedMesh& part, const Constraints& constraints) {
  const RankPieces pieces = pieces_on_ranks(part, constraints);
  if (!pieces.loose.empty())
    throw std::invalid_argument(not_held_message(pieces.loose, pieces.lowest_vertex[pieces.loose.front().piece]));
}

}  // namespace snede
