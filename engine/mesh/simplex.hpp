// The canonical oriented simplex of §7.2: vertices sorted ascending plus a sign, so that
// <a0..ak> and any even permutation of it compare equal and hash alike.
#pragma once

#include <array>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>

namespace snede {

using VertexId = std::int32_t;
inline constexpr int max_dimension = 3;

class Simplex {
 public:
  Simplex() = default;
  // (sign)·<vertices...>, canonicalised by sorting while counting swaps (§7.2).
  // Throws std::invalid_argument for a repeated vertex, a negative vertex id, a sign other
  // than ±1 or more than max_dimension + 1 vertices.
  Simplex(int sign, std::span<const VertexId> vertices);
  Simplex(int sign, std::initializer_list<VertexId> vertices)
      : Simplex(sign, std::span<const VertexId>(vertices.begin(), vertices.size())) {}

  int count() const { return n_; }
  int dimension() const { return n_ - 1; }
  int sign() const { return sign_; }
  VertexId vertex(int j) const { return v_[j]; }
  std::span<const VertexId> vertices() const { return {v_.data(), static_cast<std::size_t>(n_)}; }
  bool empty() const { return n_ == 0; }
  // Position j with vertex(j) == v, or -1 if v is not a vertex.
  int index(VertexId v) const;
  bool contains(VertexId v) const { return index(v) >= 0; }
  // True if every vertex of `other` is a vertex of this simplex (orientation ignored).
  bool contains_all(const Simplex& other) const;
  bool same_vertices(const Simplex& other) const;

  // (-1)^j · sign · <a0..ak \ aj>: the j-th face, oriented as the boundary of this simplex.
  Simplex subn(int j) const;
  // subsimplex_v: the face opposite vertex v (v must be a vertex).
  Simplex subv(VertexId v) const;
  // -σ.
  Simplex mate() const;
  // σ with v replaced by w (v must be a vertex, w must not be).
  Simplex substituted(VertexId v, VertexId w) const;
  // sign · <v, a0..ak>: the unique (k+1)-simplex containing v and σ (v must not be a vertex).
  Simplex sup(VertexId v) const;
  // Every vertex replaced by map(vertex) at once; the orientation follows the sequence.
  template <class VertexMap>
  Simplex mapped(VertexMap&& map) const {
    std::array<VertexId, max_dimension + 1> w{};
    for (int j = 0; j < n_; ++j) w[j] = map(v_[j]);
    return Simplex(sign_, std::span<const VertexId>(w.data(), n_));
  }
  // The vertices in an order of positive orientation: sorted, with the first two swapped
  // when the sign is negative.
  std::array<VertexId, max_dimension + 1> oriented_vertices() const;

  friend bool operator==(const Simplex&, const Simplex&) = default;
  friend std::strong_ordering operator<=>(const Simplex& a, const Simplex& b);

  std::string to_string() const;  // "+<0 3 7>"

 private:
  std::array<VertexId, max_dimension + 1> v_{};
  std::int8_t n_ = 0;
  std::int8_t sign_ = 1;
};

struct SimplexHash {
  std::size_t operator()(const Simplex& s) const noexcept;
};

}  // namespace snede
