// The exact predicates of frep/meshing/mesh_predicates.h: the floating-point filter of orient3d agrees
// with plain 128-bit arithmetic on nearly degenerate inputs, and improperPair judges the cases
// the simplifier meets (shared vertex, shared edge, crossing, touching).
#include <gtest/gtest.h>

#include <random>

#include "frep/meshing/mesh_predicates.h"

namespace {

using frep::exact::P;

int orient3dExact(const P& a, const P& b, const P& c, const P& d) {
  __int128 u[3], v[3], w[3];
  for (int i = 0; i < 3; ++i) u[i] = b[i] - a[i], v[i] = c[i] - a[i], w[i] = d[i] - a[i];
  __int128 det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
  return det > 0 ? 1 : (det < 0 ? -1 : 0);
}

TEST(MeshPredicates, FilteredOrientationMatchesExactNearDegenerateCases) {
  std::mt19937_64 rng(7);
  const int64_t span = int64_t(1) << 40;  // the largest lattice the predicates accept
  std::uniform_int_distribution<int64_t> coord(-span / 2, span / 2), jitter(-2, 2);
  int zero = 0, farNonZero = 0;
  for (int n = 0; n < 200000; ++n) {
    P a{coord(rng), coord(rng), coord(rng)}, b{coord(rng), coord(rng), coord(rng)}, c{coord(rng), coord(rng), coord(rng)};
    // d on the plane of a, b, c (an integer combination), nudged by at most 2 steps: the sign is
    // then decided by products near 2^123, far below the filter's reach.
    int64_t s = n % 7 - 3, t = n % 5 - 2;
    P d;
    for (int k = 0; k < 3; ++k) d[k] = a[k] + s * (b[k] - a[k]) / 4 + t * (c[k] - a[k]) / 4 + jitter(rng);
    if (n % 3 == 0)  // exactly collinear-based: d = a + (b - a), on the line
      for (int k = 0; k < 3; ++k) d[k] = 2 * b[k] - a[k];
    const int want = orient3dExact(a, b, c, d);
    ASSERT_EQ(frep::exact::orient3d(a, b, c, d), want) << n;
    zero += want == 0;
    // A well separated point (decided by the filter).
    P far = d;
    far[n % 3] += span / 8;
    ASSERT_EQ(frep::exact::orient3d(a, b, c, far), orient3dExact(a, b, c, far)) << n;
    farNonZero += orient3dExact(a, b, c, far) != 0;
  }
  EXPECT_GT(zero, 60000);  // the exact path was exercised on true zeros
  EXPECT_GT(farNonZero, 190000);
}

TEST(MeshPredicates, ImproperPairCases) {
  const P o{0, 0, 0}, x{10, 0, 0}, y{0, 10, 0}, z{0, 0, 10};
  // Shared vertex 0, the other triangle leaves the plane: proper.
  EXPECT_FALSE(frep::improperPair({0, 1, 2}, {o, x, y}, {0, 3, 4}, {o, z, P{-10, -10, 10}}));
  // Shared vertex 0, the other triangle pierces the first one: improper.
  EXPECT_TRUE(frep::improperPair({0, 1, 2}, {o, x, y}, {0, 3, 4}, {o, P{5, 5, -5}, P{5, 5, 5}}));
  // Shared vertex, coplanar, overlapping wedges: improper; coplanar disjoint wedges: proper.
  EXPECT_TRUE(frep::improperPair({0, 1, 2}, {o, x, y}, {0, 3, 4}, {o, P{10, 5, 0}, P{5, 10, 0}}));
  EXPECT_FALSE(frep::improperPair({0, 1, 2}, {o, x, y}, {0, 3, 4}, {o, P{-10, 0, 0}, P{0, -10, 0}}));
  // Shared edge: folded onto each other in the plane (improper) or opened out (proper).
  EXPECT_TRUE(frep::improperPair({0, 1, 2}, {o, x, y}, {1, 0, 3}, {x, o, P{5, 5, 0}}));
  EXPECT_FALSE(frep::improperPair({0, 1, 2}, {o, x, y}, {1, 0, 3}, {x, o, P{5, -5, 0}}));
  // No shared vertex: crossing (improper) or apart (proper).
  EXPECT_TRUE(frep::improperPair({0, 1, 2}, {o, x, y}, {3, 4, 5}, {P{2, 2, -5}, P{2, 2, 5}, P{3, 4, 5}}));
  EXPECT_FALSE(frep::improperPair({0, 1, 2}, {o, x, y}, {3, 4, 5}, {P{2, 2, 1}, P{2, 2, 5}, P{3, 4, 5}}));
}

}  // namespace
