#include "mesh/part_as_given.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace snede {
namespace {

// The counts and offsets of an all-to-all exchange (MPI's int counts), `width` numbers per item.
struct Exchange {
  std::vector<int> send_counts, send_offsets, receive_counts, receive_offsets;

  Exchange scaled(int width) const {
    Exchange e = *this;
    for (auto* v : {&e.send_counts, &e.send_offsets, &e.receive_counts, &e.receive_offsets})
      for (int& n : *v) n *= width;
    return e;
  }
  std::size_t n_sent() const { return static_cast<std::size_t>(send_offsets.back() + send_counts.back()); }
  std::size_t n_received() const {
    return static_cast<std::size_t>(receive_offsets.back() + receive_counts.back());
  }
};

std::vector<int> offsets_of(const std::vector<int>& counts) {
  std::vector<int> offsets(counts.size(), 0);
  std::partial_sum(counts.begin(), counts.end() - 1, offsets.begin() + 1);
  return offsets;
}

template <class T>
std::vector<T> exchange(MPI_Comm comm, const std::vector<T>& sent, const Exchange& e, MPI_Datatype type) {
  std::vector<T> received(e.n_received());
  MPI_Alltoallv(sent.data(), e.send_counts.data(), e.send_offsets.data(), type, received.data(),
                e.receive_counts.data(), e.receive_offsets.data(), type, comm);
  return received;
}

// The same exchange run backwards: answers in the layout of the questions that were received.
Exchange reversed(const Exchange& e) {
  return {e.receive_counts, e.receive_offsets, e.send_counts, e.send_offsets};
}

}  // namespace

double simplex_orientation(const std::vector<double>& points, int space_dim, const std::int64_t* corners,
                           int n_corners) {
  const auto at = [&](int k, int d) { return points[static_cast<std::size_t>(corners[k]) * space_dim + d]; };
  if (n_corners == 3) {
    return (at(1, 0) - at(0, 0)) * (at(2, 1) - at(0, 1)) - (at(1, 1) - at(0, 1)) * (at(2, 0) - at(0, 0));
  }
  double e[3][3];
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) e[k][d] = at(k + 1, d) - at(0, d);
  return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

DistributedMesh part_as_given(MPI_Comm comm, RankCells given, std::int64_t n_global_vertices,
                              std::int64_t n_global_cells) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const int space_dim = given.space_dim;
  // Rank r's range of vertex ids: [range_start[r], range_start[r + 1]).
  const std::int64_t n_range = static_cast<std::int64_t>(given.coordinates.size()) / space_dim;
  std::vector<std::int64_t> range_start(static_cast<std::size_t>(ranks) + 1, 0);
  MPI_Allgather(&n_range, 1, MPI_INT64_T, range_start.data() + 1, 1, MPI_INT64_T, comm);
  std::partial_sum(range_start.begin(), range_start.end(), range_start.begin());
  const std::int64_t first_in_range = range_start[static_cast<std::size_t>(rank)];

  // This rank's vertices: the ids its cells use, sorted (so grouped by the rank whose range
  // holds them); they are the questions sent to those ranks.
  std::vector<std::int64_t> ids(given.cells);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  Exchange questions;
  questions.send_counts.assign(static_cast<std::size_t>(ranks), 0);
  for (std::int64_t id : ids) {
    const auto holder = std::upper_bound(range_start.begin(), range_start.end(), id) - range_start.begin() - 1;
    ++questions.send_counts[static_cast<std::size_t>(holder)];
  }
  questions.receive_counts.assign(static_cast<std::size_t>(ranks), 0);
  MPI_Alltoall(questions.send_counts.data(), 1, MPI_INT, questions.receive_counts.data(), 1, MPI_INT, comm);
  questions.send_offsets = offsets_of(questions.send_counts);
  questions.receive_offsets = offsets_of(questions.receive_counts);
  const std::vector<std::int64_t> asked = exchange(comm, ids, questions, MPI_INT64_T);

  // Each range vertex's owner: this rank if it uses the vertex, else the lowest rank that does
  // (the questions arrive grouped by rank, in rank order).
  std::vector<int> owner(static_cast<std::size_t>(n_range), -1);
  for (int source = 0; source < ranks; ++source) {
    const auto begin = static_cast<std::size_t>(questions.receive_offsets[static_cast<std::size_t>(source)]);
    const auto end = begin + static_cast<std::size_t>(questions.receive_counts[static_cast<std::size_t>(source)]);
    for (std::size_t q = begin; q < end; ++q) {
      int& o = owner[static_cast<std::size_t>(asked[q] - first_in_range)];
      if (o < 0 || source == rank) o = source;
    }
  }
  std::int64_t unused = std::count(owner.begin(), owner.end(), -1);
  MPI_Allreduce(MPI_IN_PLACE, &unused, 1, MPI_INT64_T, MPI_SUM, comm);
  if (unused)
    throw std::invalid_argument("distribute_cells: " + std::to_string(unused) + " of the " +
                                std::to_string(n_global_vertices) + " vertices are in no cell");

  // Answers: each asked vertex's owner and coordinates.
  const Exchange answers = reversed(questions);
  std::vector<int> owner_answer(asked.size());
  std::vector<double> coordinate_answer(asked.size() * static_cast<std::size_t>(space_dim));
  for (std::size_t q = 0; q < asked.size(); ++q) {
    const auto v = static_cast<std::size_t>(asked[q] - first_in_range);
    owner_answer[q] = owner[v];
    std::copy_n(given.coordinates.begin() + static_cast<std::ptrdiff_t>(v * space_dim), space_dim,
                coordinate_answer.begin() + static_cast<std::ptrdiff_t>(q * space_dim));
  }
  std::vector<double>().swap(given.coordinates);
  const std::vector<int> my_owner = exchange(comm, owner_answer, answers, MPI_INT);
  std::vector<double> points = exchange(comm, coordinate_answer, answers.scaled(space_dim), MPI_DOUBLE);
  std::vector<double>().swap(coordinate_answer);

  // PETSc's numbering: the owned vertices contiguously in rank order, then each ghost's number
  // from its owner, through the range ranks again.
  std::vector<std::uint8_t> owned(ids.size());
  std::int64_t n_owned = 0;
  for (std::size_t v = 0; v < ids.size(); ++v) n_owned += owned[v] = my_owner[v] == rank;
  std::int64_t first_number = 0;
  MPI_Exscan(&n_owned, &first_number, 1, MPI_INT64_T, MPI_SUM, comm);
  if (rank == 0) first_number = 0;  // MPI_Exscan leaves rank 0's undefined
  std::vector<std::int64_t> global_number(ids.size(), -1);
  for (std::size_t v = 0, next = 0; v < ids.size(); ++v)
    if (owned[v]) global_number[v] = first_number + static_cast<std::int64_t>(next++);
  const std::vector<std::int64_t> told = exchange(comm, global_number, questions, MPI_INT64_T);
  std::vector<std::int64_t> number_in_range(static_cast<std::size_t>(n_range), -1);
  for (std::size_t q = 0; q < asked.size(); ++q)
    if (told[q] >= 0) number_in_range[static_cast<std::size_t>(asked[q] - first_in_range)] = told[q];
  std::vector<std::int64_t> number_answer(asked.size());
  for (std::size_t q = 0; q < asked.size(); ++q)
    number_answer[q] = number_in_range[static_cast<std::size_t>(asked[q] - first_in_range)];
  global_number = exchange(comm, number_answer, answers, MPI_INT64_T);

  // The cells by local vertex id (the rank of the global id among the sorted ids), positively
  // oriented; a membrane's triangle (in 3D) keeps its corners' order: it has no signed area.
  const int corners = given.cell_dim + 1;
  std::vector<std::int64_t>& cells = given.cells;
  for (std::int64_t& v : cells) v = std::lower_bound(ids.begin(), ids.end(), v) - ids.begin();
  if (given.cell_dim == space_dim)
    for (std::size_t c = 0; c < cells.size(); c += static_cast<std::size_t>(corners))
      if (simplex_orientation(points, space_dim, &cells[c], corners) < 0) std::swap(cells[c], cells[c + 1]);

  return DistributedMesh{.comm = comm,
                         .local = std::make_unique<Mesh>(given.cell_dim, space_dim, std::move(points), cells),
                         .global_vertex = std::move(ids),
                         .owned = std::move(owned),
                         .global_number = std::move(global_number),
                         .n_global_vertices = n_global_vertices,
                         .n_global_cells = n_global_cells};
}

}  // namespace snede
