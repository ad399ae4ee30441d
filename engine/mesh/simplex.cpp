#include "mesh/simplex.hpp"

#include <sstream>
#include <stdexcept>

namespace snede {

Simplex::Simplex(int sign, std::span<const VertexId> vertices) {
  if (sign != 1 && sign != -1)
    throw std::invalid_argument("Simplex: sign must be +1 or -1, got " + std::to_string(sign));
  if (vertices.empty() || vertices.size() > static_cast<std::size_t>(max_dimension + 1))
    throw std::invalid_argument("Simplex: needs 1 to " + std::to_string(max_dimension + 1) +
                                " vertices, got " + std::to_string(vertices.size()));
  n_ = static_cast<std::int8_t>(vertices.size());
  int swaps = 0;
  // Insertion sort: at most 6 swaps for 4 vertices, and it counts them (§7.2).
  for (int i = 0; i < n_; ++i) {
    if (vertices[i] < 0)
      throw std::invalid_argument("Simplex: negative vertex id " + std::to_string(vertices[i]));
    v_[i] = vertices[i];
    for (int j = i; j > 0 && v_[j - 1] > v_[j]; --j) {
      std::swap(v_[j - 1], v_[j]);
      ++swaps;
    }
  }
  for (int i = 1; i < n_; ++i)
    if (v_[i - 1] == v_[i])
      throw std::invalid_argument("Simplex: vertex " + std::to_string(v_[i]) + " is repeated");
  sign_ = static_cast<std::int8_t>(swaps % 2 == 0 ? sign : -sign);
}

int Simplex::index(VertexId v) const {
  for (int j = 0; j < n_; ++j)
    if (v_[j] == v) return j;
  return -1;
}

bool Simplex::contains_all(const Simplex& other) const {
  for (VertexId v : other.vertices())
    if (!contains(v)) return false;
  return true;
}

bool Simplex::same_vertices(const Simplex& other) const {
  return n_ == other.n_ && v_ == other.v_;
}

Simplex Simplex::subn(int j) const {
  Simplex face;
  face.n_ = static_cast<std::int8_t>(n_ - 1);
  for (int i = 0, k = 0; i < n_; ++i)
    if (i != j) face.v_[k++] = v_[i];
  face.sign_ = static_cast<std::int8_t>(j % 2 == 0 ? sign_ : -sign_);
  return face;
}

Simplex Simplex::subv(VertexId v) const {
  const int j = index(v);
  if (j < 0) throw std::invalid_argument("Simplex::subv: " + std::to_string(v) + " not in " + to_string());
  return subn(j);
}

Simplex Simplex::mate() const {
  Simplex m = *this;
  m.sign_ = static_cast<std::int8_t>(-sign_);
  return m;
}

Simplex Simplex::substituted(VertexId v, VertexId w) const {
  if (!contains(v))
    throw std::invalid_argument("Simplex::substituted: " + std::to_string(v) + " not in " + to_string());
  return mapped([v, w](VertexId x) { return x == v ? w : x; });
}

Simplex Simplex::sup(VertexId v) const {
  if (contains(v))
    throw std::invalid_argument("Simplex::sup: " + std::to_string(v) + " already in " + to_string());
  std::array<VertexId, max_dimension + 1> w{};
  w[0] = v;
  for (int j = 0; j < n_; ++j) w[j + 1] = v_[j];
  return Simplex(sign_, std::span<const VertexId>(w.data(), n_ + 1));
}

std::array<VertexId, max_dimension + 1> Simplex::oriented_vertices() const {
  auto w = v_;
  if (sign_ < 0 && n_ >= 2) std::swap(w[0], w[1]);
  return w;
}

std::strong_ordering operator<=>(const Simplex& a, const Simplex& b) {
  if (auto c = a.n_ <=> b.n_; c != 0) return c;
  for (int j = 0; j < a.n_; ++j)
    if (auto c = a.v_[j] <=> b.v_[j]; c != 0) return c;
  return a.sign_ <=> b.sign_;
}

std::string Simplex::to_string() const {
  std::ostringstream out;
  out << (sign_ > 0 ? '+' : '-') << '<';
  for (int j = 0; j < n_; ++j) out << (j ? " " : "") << v_[j];
  out << '>';
  return out.str();
}

std::size_t SimplexHash::operator()(const Simplex& s) const noexcept {
  // 64-bit mix of the sorted vertices and the sign (splitmix64 finaliser per word).
  std::uint64_t h = static_cast<std::uint64_t>(s.sign() > 0 ? 0x9e3779b97f4a7c15ULL : 0x632be59bd9b4e019ULL);
  for (VertexId v : s.vertices()) {
    h ^= static_cast<std::uint64_t>(static_cast<std::uint32_t>(v)) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    h ^= h >> 31;
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 29;
  }
  return static_cast<std::size_t>(h);
}

}  // namespace snede
