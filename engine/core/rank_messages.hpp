// Messages from every rank to every rank in one exchange (collective): each rank gives one list
// per destination, counts go first (MPI_Alltoall), then the lists (MPI_Alltoallv).
#pragma once

#include <mpi.h>

#include <numeric>
#include <vector>

namespace snede {

// What this rank received, every sender's list one after another in rank order. `type` is
// T's MPI datatype (MPI_INT64_T, MPIU_INT, ...); outgoing has one list per rank of comm.
template <class T>
std::vector<T> exchange_messages(MPI_Comm comm, const std::vector<std::vector<T>>& outgoing, MPI_Datatype type) {
  const int size = static_cast<int>(outgoing.size());
  std::vector<int> send_counts(size), receive_counts(size), send_starts(size + 1, 0), receive_starts(size + 1, 0);
  for (int r = 0; r < size; ++r) send_counts[r] = static_cast<int>(outgoing[r].size());
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, comm);
  std::partial_sum(send_counts.begin(), send_counts.end(), send_starts.begin() + 1);
  std::partial_sum(receive_counts.begin(), receive_counts.end(), receive_starts.begin() + 1);
  std::vector<T> sent, received(static_cast<std::size_t>(receive_starts[size]));
  sent.reserve(static_cast<std::size_t>(send_starts[size]));
  for (const auto& message : outgoing) sent.insert(sent.end(), message.begin(), message.end());
  MPI_Alltoallv(sent.data(), send_counts.data(), send_starts.data(), type, received.data(), receive_counts.data(),
                receive_starts.data(), type, comm);
  return received;
}

}  // namespace snede
