#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <unordered_set>

#include "mesh/simplex.hpp"

using snede::Simplex;
using snede::SimplexHash;

TEST(Simplex, CanonicalFormSortsAndCountsSwaps) {
  const Simplex s(1, {3, 1, 2});  // <3 1 2> is an even permutation of <1 2 3>
  EXPECT_EQ(s.sign(), 1);
  EXPECT_EQ(s.vertex(0), 1);
  EXPECT_EQ(s.vertex(2), 3);
  EXPECT_EQ(Simplex(1, {2, 1, 3}).sign(), -1);  // one swap
  EXPECT_EQ(Simplex(-1, {2, 1, 3}), Simplex(1, {1, 2, 3}));
  EXPECT_EQ(s.count(), 3);
  EXPECT_EQ(s.dimension(), 2);
}

TEST(Simplex, AllEvenPermutationsAreEqualAllOddOpposite) {
  std::array<snede::VertexId, 4> v{7, 2, 9, 4};
  const Simplex reference(1, v);
  std::sort(v.begin(), v.end());
  do {
    // parity of the permutation from {2 4 7 9} to v, counted by inversions
    int inversions = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) inversions += v[i] > v[j];
    const Simplex s(1, v);
    const Simplex sorted_positive(1, {2, 4, 7, 9});
    EXPECT_EQ(s, inversions % 2 == 0 ? sorted_positive : sorted_positive.mate());
  } while (std::next_permutation(v.begin(), v.end()));
  EXPECT_TRUE(reference.same_vertices(Simplex(1, {2, 4, 7, 9})));
}

TEST(Simplex, SubnFollowsTheBoundaryOperator) {
  // ∂<a b c> = <b c> - <a c> + <a b>
  const Simplex t(1, {0, 1, 2});
  EXPECT_EQ(t.subn(0), Simplex(1, {1, 2}));
  EXPECT_EQ(t.subn(1), Simplex(-1, {0, 2}));
  EXPECT_EQ(t.subn(2), Simplex(1, {0, 1}));
  EXPECT_EQ(t.subv(1), t.subn(1));
  // ∂∂ = 0: every edge of a tetrahedron appears twice with opposite signs among its faces' faces.
  const Simplex tet(1, {0, 1, 2, 3});
  std::map<Simplex, int> count;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j) {
      const Simplex e = tet.subn(i).subn(j);
      const Simplex key = e.sign() > 0 ? e : e.mate();
      count[key] += e.sign();
    }
  EXPECT_EQ(count.size(), 6u);
  for (const auto& [edge, sum] : count) EXPECT_EQ(sum, 0) << edge.to_string();
}

TEST(Simplex, SupIsInverseOfSubv) {
  const Simplex face(-1, {5, 2, 8});
  for (snede::VertexId v : {0, 3, 6, 9}) {
    const Simplex up = face.sup(v);
    EXPECT_EQ(up.count(), 4);
    EXPECT_EQ(up.subv(v), face) << v;
  }
  EXPECT_THROW(face.sup(5), std::invalid_argument);
}

TEST(Simplex, SubstitutedAndMapped) {
  const Simplex t(1, {0, 1, 2});
  EXPECT_EQ(t.substituted(0, 5), Simplex(1, {5, 1, 2}));
  EXPECT_EQ(t.substituted(0, 5).sign(), 1);  // <1 2 5> is an even permutation of <5 1 2>
  EXPECT_THROW(t.substituted(0, 1), std::invalid_argument);  // would repeat 1
  EXPECT_THROW(t.substituted(7, 8), std::invalid_argument);
  // simultaneous swap of two vertices flips the orientation
  EXPECT_EQ(t.mapped([](snede::VertexId v) { return v == 0 ? 1 : v == 1 ? 0 : v; }), t.mate());
}

TEST(Simplex, MateIndexContainsOrientedVertices) {
  const Simplex t(1, {4, 2, 6});
  EXPECT_EQ(t.mate().mate(), t);
  EXPECT_NE(t.mate(), t);
  EXPECT_EQ(t.index(6), 2);
  EXPECT_EQ(t.index(5), -1);
  EXPECT_TRUE(t.contains_all(Simplex(1, {2, 6})));
  const auto o = t.mate().oriented_vertices();
  EXPECT_EQ(Simplex(1, {o[0], o[1], o[2]}), t.mate());
}

TEST(Simplex, RejectsBadInput) {
  EXPECT_THROW(Simplex(1, {1, 2, 1}), std::invalid_argument);
  EXPECT_THROW(Simplex(0, {1, 2}), std::invalid_argument);
  EXPECT_THROW(Simplex(1, {1, 2, 3, 4, 5}), std::invalid_argument);
  EXPECT_THROW(Simplex(1, {-1, 2}), std::invalid_argument);
}

TEST(Simplex, OrderingAndHashAgreeWithEquality) {
  std::vector<Simplex> all;
  for (int a = 0; a < 5; ++a)
    for (int b = a + 1; b < 5; ++b)
      for (int sign : {1, -1}) all.push_back(Simplex(sign, {b, a}));
  std::unordered_set<Simplex, SimplexHash> set(all.begin(), all.end());
  EXPECT_EQ(set.size(), all.size());
  std::sort(all.begin(), all.end());
  EXPECT_EQ(std::adjacent_find(all.begin(), all.end()), all.end());
  EXPECT_LT(Simplex(1, {0, 1}), Simplex(1, {0, 2}));
  EXPECT_LT(Simplex(1, {0, 1}), Simplex(1, {0, 1, 2}));  // lower dimension first
}
