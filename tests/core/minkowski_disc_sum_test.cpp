// Sums with discs on three axes, or on two with a sphere (Roerdink-Minkowski Theorem 5's
// R12–R16): the convex-projection distance (disc_sum_distance.h) against closed forms on the
// coordinate planes, the dual bound, the bidisc gauge's sign, its Lipschitz constant and interval
// bound, volumes against mixed-volume formulas of zonoids, and the ray-tracer primitives.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frep/minkowski_algebra/bidisc.h"
#include "frep/minkowski_algebra/disc_sum_distance.h"
#include "frep/minkowski_algebra/reduction.h"
#include "minkowski_test_shapes.h"

namespace frep::minkowski {
namespace {

using namespace test_shapes;

Vec3 randomRadii(std::mt19937& rng, int trial) {
  std::uniform_real_distribution<double> u(0.05, 1.0);
  Vec3 r{u(rng), u(rng), u(rng)};
  if (trial % 3 == 0) r[trial % 2] = 0;            // two axes (a bidisc, with a ball: bicircle-sphere)
  if (trial % 7 == 0) r[(trial / 7) % 3] *= 1e-3;  // a thin one
  return r;
}

// On the plane x_k = 0 the nearest point of D is in that plane (D is symmetric in it and convex),
// and D's section there is the rectangle of half-widths (r_j, r_i) along (i, j) ⊕ disc(r_k):
// the distance is a rounded rectangle's, in closed form.
TEST(MinkowskiDiscSum, DistanceOnTheCoordinatePlanesIsTheRoundedRectangles) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  int outside = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    DiscSum d{randomRadii(rng, trial)};
    const int k = trial % 3, i = (k + 1) % 3, j = (k + 2) % 3;
    Vec3 q{u(rng), u(rng), u(rng)};
    q[k] = 0;
    const double ei = std::max(std::fabs(q[i]) - d.r[j], 0.0), ej = std::max(std::fabs(q[j]) - d.r[i], 0.0);
    const double expected = std::hypot(ei, ej) - d.r[k];
    const DiscSum::Distance got = d.distance(q);
    if (expected <= 1e-9) continue;
    ASSERT_FALSE(got.inside) << trial;
    ASSERT_NEAR(got.lo, expected, 1e-12) << trial;
    double err;
    ASSERT_NEAR(d.signedDistance(q, 0.3, &err), expected - 0.3, 1e-12) << trial;
    ASSERT_LE(err, 1e-12) << trial;
    ++outside;
  }
  EXPECT_GT(outside, 10000);
}

// Off the planes: the distance is certified (lo <= dist <= hi, hi − lo at rounding) and no unit
// direction n gives a larger lower bound n·q − h(n); h itself against a brute-force max over the
// three circles.
TEST(MinkowskiDiscSum, DistanceIsTheDualMaximumAndCertified) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  int outside = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    DiscSum d{randomRadii(rng, trial)};
    const Vec3 q{2 * u(rng), 2 * u(rng), 2 * u(rng)};
    const DiscSum::Distance got = d.distance(q);
    const Vec3 aq{std::fabs(q[0]), std::fabs(q[1]), std::fabs(q[2])};
    double best = -INFINITY;
    for (int s = 0; s < 400; ++s) {
      Vec3 n{u(rng), u(rng), u(rng)};
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (len < 1e-3) continue;
      for (double& c : n) c /= len;
      best = std::max(best, n[0] * aq[0] + n[1] * aq[1] + n[2] * aq[2] - d.support(n));
    }
    if (got.inside) {
      EXPECT_LE(best, 1e-12) << trial;  // no separating direction
      continue;
    }
    ++outside;
    const double scale = std::fabs(q[0]) + std::fabs(q[1]) + std::fabs(q[2]) + d.r[0] + d.r[1] + d.r[2];
    EXPECT_LE(got.hi - got.lo, 1e-9 * scale) << trial;
    EXPECT_GE(got.lo, best - 1e-13) << trial;
    if (trial % 10 == 0) {  // the support function: max over the circles' points, per circle
      double brute = 0;
      for (int c = 0; c < 3; ++c) {
        const int a = (c + 1) % 3, b = (c + 2) % 3;
        double m = 0;
        for (int t = 0; t < 3600; ++t)
          m = std::max(m, d.r[c] * (got.n[a] * std::cos(2 * kPi * t / 3600) + got.n[b] * std::sin(2 * kPi * t / 3600)));
        brute += m;
      }
      EXPECT_NEAR(d.support(got.n), brute, 1e-5 * (1 + brute)) << trial;
    }
  }
  EXPECT_GT(outside, 1000);
}

// With one radius 0, D is the bidisc, whose membership has the closed-form gauge of bidisc.h.
TEST(MinkowskiDiscSum, SignIsTheBidiscGauges) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.2, 1.2), r(0.05, 0.8);
  int compared = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double a = r(rng), b = r(rng);
    const Vec3 q{u(rng), u(rng), u(rng)};
    const double g = bidiscGauge(std::fabs(q[0]), std::fabs(q[1]), std::fabs(q[2]), a, b);
    if (std::fabs(g) < 1e-9) continue;
    double err;
    const double sd = DiscSum{{a, b, 0}}.signedDistance(q, 0, &err);
    ASSERT_EQ(g > 0, sd < 0) << trial << ": gauge " << g << ", signed distance " << sd;
    ++compared;
  }
  EXPECT_GT(compared, 19000);
}

// The field is 1-Lipschitz (exact distance outside, ball + r(1 − γ) inside) and its interval
// bound encloses every value in the box.
TEST(MinkowskiDiscSum, FieldIsOneLipschitzAndItsBoundIsSound) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1), l(0, 1);
  double worst = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 len{trial % 2 ? l(rng) : 0.0, l(rng), trial % 3 ? l(rng) : 0.0};
    const DiscSumField f(len, randomRadii(rng, trial), trial % 4 ? 0.2 * l(rng) : 0.0);
    for (int s = 0; s < 200; ++s) {
      const double p[3] = {2 * u(rng), 2 * u(rng), 2 * u(rng)};
      double q[3];
      const double step = s % 2 ? 1e-3 : 0.5;
      for (int i = 0; i < 3; ++i) q[i] = p[i] + step * u(rng);
      const double dist = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                    (p[2] - q[2]) * (p[2] - q[2]));
      worst = std::max(worst, std::fabs(f.value(p) - f.value(q)) / dist);
    }
    for (int s = 0; s < 20; ++s) {
      Interval box[3];
      for (int i = 0; i < 3; ++i) {
        const double c = 2 * u(rng), h = 0.3 * l(rng);
        box[i] = {c - h, c + h};
      }
      const Interval b = f.bound(box);
      for (int t = 0; t < 20; ++t) {
        double p[3];
        for (int i = 0; i < 3; ++i) p[i] = box[i].lo + (box[i].hi - box[i].lo) * l(rng);
        const double v = f.value(p);
        ASSERT_GE(v, b.lo);
        ASSERT_LE(v, b.hi);
      }
    }
  }
  EXPECT_LE(worst, 1 + 1e-9);
}

// Mixed volumes of zonoids: a disc of radius r is the zonoid of the segments [−u, u], u on its
// circle, with density r/4 dθ (∫|n·u| r/4 dθ = r|P n|), a ball the one with density 1/(2π) dσ;
// V(Z1, Z2, Z3) = 4/3 ∭ |det(u, v, w)| dμ1 dμ2 dμ3. So V(Dx, Dy, Dz) = 1/48 ∭ |det| dα dβ dγ and
// V(Dx, Dy, B) = 1/12 ∬ |u × v| dα dβ (∫ |x·w| dσ(w) = 2π|x|); midpoint rules below.
double mixedDiscs() {
  const int n = 160;
  const double h = 2 * kPi / n;
  double s = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double a = (i + 0.5) * h, b = (j + 0.5) * h, c = (k + 0.5) * h;
        // u = (0, cos a, sin a), v = (cos b, 0, sin b), w = (cos c, sin c, 0)
        const double det = -std::cos(a) * (0 - std::sin(b) * std::cos(c)) + std::sin(a) * (std::cos(b) * std::sin(c));
        s += std::fabs(det);
      }
  return s * h * h * h / 48;
}
double mixedTwoDiscsBall() {
  const int n = 800;
  const double h = 2 * kPi / n;
  double s = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double sa = std::sin((i + 0.5) * h), sb = std::sin((j + 0.5) * h);
      s += std::sqrt(1 - sa * sa * sb * sb);  // |u × v|² = 1 − (u·v)²
    }
  return s * h * h / 12;
}

TEST(MinkowskiDiscSum, VolumesMatchTheMixedVolumeFormulas) {
  // The method reproduces the bidisc's known coefficient: V(Dx, Dx, Dy) = 2π/3 (2πab(a + b)).
  // Rotated block ⊕ xdisc(a) ⊕ ydisc(b) ⊕ zdisc(c): LxLyLz + Σ L_j L_k w_i + Σ L_i A_i + V(D),
  // w_i = 2 Σ_{j≠i} r_j (D's width), A_i = π r_i² + 4 r_i (r_j + r_k) + 4 r_j r_k (its shadow
  // along i: disc(r_i) ⊕ a rectangle), V(D) = 2π Σ_{i≠j} r_i² r_j + 6abc V(Dx, Dy, Dz).
  const double vxyz = mixedDiscs();
  const double lx = 0.7, ly = 0.5, lz = 0.3, r[3] = {0.3, 0.2, 0.25};
  const Mat3 rot = rotationXYZ(0.4, -0.3, 0.7);
  Sum s;
  s.add(member(ShapeKind::Segment, 0, lx, rot));
  s.add(member(ShapeKind::Segment, 1, -ly, rot));
  s.add(member(ShapeKind::Segment, 2, lz, rot));
  for (int i = 0; i < 3; ++i) s.add(member(ShapeKind::Disc, i, r[i], rot));
  const double L[3] = {lx, ly, lz};
  double v = lx * ly * lz, vd = 6 * r[0] * r[1] * r[2] * vxyz;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    v += L[j] * L[k] * 2 * (r[j] + r[k]);
    v += L[i] * (kPi * r[i] * r[i] + 4 * r[i] * (r[j] + r[k]) + 4 * r[j] * r[k]);
    vd += 2 * kPi * r[i] * r[i] * (r[j] + r[k]);
  }
  EXPECT_NEAR(latticeVolume(reduce(s), 120) / (v + vd), 1.0, 5e-3);
  // Steiner: V(K ⊕ sB) = V(K) + S(K) s + M(K) s² + 4π/3 s³ for the bidisc K = xdisc(a) ⊕ ydisc(b):
  // S = 2πa² + 2πb² + 6ab V(Dx, Dy, B), M = π²(a + b) (2π × the mean width πr/2 per disc).
  const double a = 0.45, b = 0.3, sb = 0.15;
  Sum bs;
  bs.add(member(ShapeKind::Disc, 0, a));
  bs.add(member(ShapeKind::Disc, 1, b));
  bs.add(member(ShapeKind::Sphere, 0, sb));
  const double area = 2 * kPi * (a * a + b * b) + 6 * a * b * mixedTwoDiscsBall();
  const double vbs = 2 * kPi * a * b * (a + b) + area * sb + kPi * kPi * (a + b) * sb * sb + 4 * kPi / 3 * sb * sb * sb;
  EXPECT_NEAR(latticeVolume(reduce(bs), 120) / vbs, 1.0, 5e-3);
}

// The ray-tracer form (6 blocks, 12 cylinders, 8 tridiscspheres; fewer when sizes vanish) holds
// exactly the points where the field is >= 0.
TEST(MinkowskiDiscSum, PrimitivesAreTheSum) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(0, 1);
  struct Case {
    Vec3 L, r;
    double s;
    size_t count;
  };
  const Case cases[] = {
      {{0.8, 0.5, 0.3}, {0.3, 0.2, 0.25}, 0.1, 26},  // Appendix B's B*
      {{0.8, 0.5, 0.3}, {0.3, 0.2, 0.25}, 0.0, 26},  // block ⊕ tricircle
      {{0.8, 0.5, 0.3}, {0.3, 0.2, 0.0}, 0.1, 25},   // block ⊕ bicircle-sphere (two blocks coincide)
      {{0, 0, 0}, {0.3, 0.2, 0.25}, 0.1, 1},         // the tricircle-sphere's hull alone
      {{0, 0, 0}, {0.3, 0.0, 0.25}, 0.1, 1},         // the bicircle-sphere's hull alone
      {{0.8, 0, 0}, {0.3, 0.2, 0.25}, 0.0, 8},       // xline ⊕ tricircle: 2 blocks, 4 cylinders, 2 ends
      {{0.8, 0.5, 0}, {0.3, 0.2, 0.25}, 0.1, 16},    // rectangle: 2 + 4 along x and along y, 4 corners
  };
  for (const Case& c : cases) {
    Sum s;
    for (int i = 0; i < 3; ++i) {
      if (c.L[i] > 0) s.add(member(ShapeKind::Segment, i, c.L[i]));
      if (c.r[i] > 0) s.add(member(ShapeKind::Disc, i, c.r[i]));
    }
    if (c.s > 0) s.add(member(ShapeKind::Sphere, 0, c.s));
    Reduction red = reduce(s);
    ASSERT_TRUE(red.ok);
    ASSERT_EQ(red.count(PieceKind::DiscSum), 1);
    const std::vector<Piece> prims = primitives(red);
    EXPECT_EQ(prims.size(), c.count) << s.describe();
    EXPECT_LE(prims.size(), 35u);  // Theorem 5 / §IV.F
    int checked = 0;
    for (int t = 0; t < 3000; ++t) {
      Vec3 p;
      for (int i = 0; i < 3; ++i) p[i] = -1.2 + (c.L[i] + 2.4) * u(rng);
      const double f = unionValue(red, p);
      if (std::fabs(f) < 1e-9) continue;
      bool held = false;
      for (const Piece& q : prims) held = held || primitiveHolds(q, p);
      ASSERT_EQ(held, f > 0) << s.describe() << " at (" << p[0] << ", " << p[1] << ", " << p[2] << "), f " << f;
      ++checked;
    }
    EXPECT_GT(checked, 2900);
  }
}

}  // namespace
}  // namespace frep::minkowski
