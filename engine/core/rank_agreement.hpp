// Collective calls must be entered by every rank with the same arguments: a rank that throws
// alone, or solves to another tolerance, leaves the others waiting in a reduction for ever.
// A digest of the arguments is compared across the ranks before anything can differ, and a
// mismatch is the same std::invalid_argument on every rank (issue 18).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

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
  InputDigest& add(double value) { return add(std::span<const double>(&value, 1)); }
  InputDigest& add(const std::string& text) { return add(std::span<const char>(text.data(), text.size())); }
  std::uint64_t value() const { return hash_; }

 private:
  void mix(unsigned char byte) { hash_ = (hash_ ^ byte) * 1099511628211ULL; }
  std::uint64_t hash_ = 14695981039346656037ULL;
};

// Collective: throws std::invalid_argument "<what>: the ranks were given different
// <inputs>; every rank must pass the same" on every rank unless the digests agree.
inline void require_same_on_every_rank(MPI_Comm comm, const InputDigest& digest, const std::string& what,
                                       const std::string& inputs) {
  std::uint64_t low = digest.value(), high = digest.value();
  MPI_Allreduce(MPI_IN_PLACE, &low, 1, MPI_UINT64_T, MPI_MIN, comm);
  MPI_Allreduce(MPI_IN_PLACE, &high, 1, MPI_UINT64_T, MPI_MAX, comm);
  if (low != high)
    throw std::invalid_argument(what + ": the ranks were given different inputs (" + inputs +
                                "); every rank must pass the same");
}

}  // namespace snede
