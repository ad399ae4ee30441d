// Collective calls must be entered by every rank with the same arguments: a rank that throws
// alone, or solves to another tolerance, leaves the others waiting in a reduction for ever.
// A digest of each argument is compared across the ranks before anything can differ, and a
// mismatch is the same std::invalid_argument on every rank, naming the arguments that differ
// (issue 18; named since issue 38).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace snede {

// FNV-1a over the bytes of every value added, with each sequence's length.
class InputDigest {
 public:
  template <class T>
  InputDigest& add(std::span<const T> values) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
    for (std::size_t i = 0; i < values.size_bytes(); ++i) mix(bytes[i]);
    const std::uint64_t size = values.size();  // separates [a][b, c] from [a, b][c]
    for (int shift = 0; shift < 64; shift += 8) mix(static_cast<unsigned char>(size >> shift));
    return *this;
  }
  template <class T>
  InputDigest& add(const std::vector<T>& values) { return add(std::span<const T>(values)); }
  InputDigest& add(double value) { return add(std::span<const double>(&value, 1)); }
  InputDigest& add(const std::string& text) { return add(std::span<const char>(text.data(), text.size())); }
  std::uint64_t value() const { return hash_; }

 private:
  void mix(unsigned char byte) { hash_ = (hash_ ^ byte) * 1099511628211ULL; }
  std::uint64_t hash_ = 14695981039346656037ULL;
};

// The named inputs of one collective call, which every rank must give alike:
//   RankAgreement("DistributedStatic.solve").input("method", method).input("rtol", rtol).require(comm);
class RankAgreement {
 public:
  explicit RankAgreement(std::string caller) : caller_(std::move(caller)) {}

  RankAgreement& input(std::string name, const InputDigest& digest) {
    names_.push_back(std::move(name));
    digests_.push_back(digest.value());
    return *this;
  }
  template <class T>
  RankAgreement& input(std::string name, const T& value) {
    return input(std::move(name), InputDigest().add(value));
  }

  // Collective (every rank names the same inputs, in the same order): throws
  // std::invalid_argument "<caller>: the ranks were given different inputs (<name>: rank r
  // differs from rank 0; ...); every rank must pass the same" on every rank unless every
  // rank's digests are rank 0's. r is the lowest rank whose input differs.
  void require(MPI_Comm comm) const {
    int n_ranks = 1;
    MPI_Comm_size(comm, &n_ranks);
    const std::size_t n = digests_.size();
    std::vector<std::uint64_t> every_rank(n * static_cast<std::size_t>(n_ranks));
    MPI_Allgather(digests_.data(), static_cast<int>(n), MPI_UINT64_T, every_rank.data(), static_cast<int>(n),
                  MPI_UINT64_T, comm);
    std::string differences;
    for (std::size_t k = 0; k < n; ++k)
      for (int rank = 1; rank < n_ranks; ++rank)
        if (every_rank[static_cast<std::size_t>(rank) * n + k] != every_rank[k]) {
          differences += (differences.empty() ? "" : "; ") + names_[k] + ": rank " + std::to_string(rank) +
                         " differs from rank 0";
          break;
        }
    if (!differences.empty())
      throw std::invalid_argument(caller_ + ": the ranks were given different inputs (" + differences +
                                  "); every rank must pass the same");
  }

 private:
  std::string caller_;
  std::vector<std::string> names_;
  std::vector<std::uint64_t> digests_;
};

// Collective: the problem the lowest rank found (`problem` empty where a rank found none),
// prefixed "<caller>: rank r: ", the same on every rank; empty when no rank found any. A rank
// that finds a problem throws it only after this, so no rank waits alone.
inline std::string first_rank_problem(MPI_Comm comm, const std::string& caller, std::string problem) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int first = problem.empty() ? std::numeric_limits<int>::max() : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == std::numeric_limits<int>::max()) return "";
  if (rank == first) problem = caller + ": rank " + std::to_string(rank) + ": " + problem;
  int length = static_cast<int>(problem.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  problem.resize(static_cast<std::size_t>(length));
  MPI_Bcast(problem.data(), length, MPI_CHAR, first, comm);
  return problem;
}

}  // namespace snede
