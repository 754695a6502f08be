// Sums with discs on two axes (core/src/minkowski_algebra/bidisc.cpp): the closed-form gauge
// against a brute-force maximisation and the certified search, its Lipschitz bound, the
// ray-tracer primitives (bicircles, cylinders, blocks) against the gauge, and the volume of
// block ⊕ bidisc against its mixed-volume formula.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "frep/extremum/extremum.h"
#include "frep/minkowski_algebra/bidisc.h"
#include "frep/minkowski_algebra/reduction.h"
#include "minkowski_test_shapes.h"

namespace frep::minkowski {
namespace {

using namespace test_shapes;

// max over t in [0, h] of min(a − |(w, t)|, b − |(u, h − t)|), by ternary search (the min of a
// falling and a rising function is unimodal), written without the quadratic.
double bruteGauge(double u, double w, double h, double a, double b) {
  auto f = [&](double t) { return std::min(a - std::hypot(w, t), b - std::hypot(u, h - t)); };
  double lo = 0, hi = h;
  for (int i = 0; i < 200; ++i) {
    double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    (f(m1) < f(m2) ? lo : hi) = f(m1) < f(m2) ? m1 : m2;
  }
  return std::max({f(0), f(h), f(0.5 * (lo + hi))});
}

TEST(MinkowskiBidisc, GaugeIsTheMaxOverTheSplit) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  const Expr x0 = Expr::x(0), x1 = Expr::x(1), x2 = Expr::x(2);
  PointEvaluator pe;
  for (int trial = 0; trial < 20; ++trial) {
    const double a = 0.05 + u(rng), b = trial % 4 == 0 ? a : 0.05 + u(rng);
    TapePtr t = Tape::compile(bidiscGauge(x0, x1, x2, a, b), 3);
    for (int i = 0; i < 1000; ++i) {
      double p[3] = {2 * u(rng) * u(rng), 2 * u(rng) * u(rng), 3 * u(rng) * u(rng)};
      if (i % 10 == 0) p[i % 3] = 0;
      const double g = bidiscGauge(p[0], p[1], p[2], a, b);
      ASSERT_NEAR(g, bruteGauge(p[0], p[1], p[2], a, b), 1e-9)
          << "a " << a << " b " << b << " at " << p[0] << " " << p[1] << " " << p[2];
      ASSERT_NEAR(pe.eval(*t, p), g, 1e-12);
    }
  }
}

TEST(MinkowskiBidisc, GaugeIsOneLipschitz) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  double worst = 0;
  for (int i = 0; i < 200000; ++i) {
    const double a = 0.2 + std::fabs(u(rng)) / 2, b = 0.2 + std::fabs(u(rng)) / 2;
    double p[3] = {u(rng), u(rng), u(rng)}, q[3];
    const double step = i % 2 ? 1e-3 : 0.3;
    for (int k = 0; k < 3; ++k) q[k] = p[k] + step * u(rng);
    const double d = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                               (p[2] - q[2]) * (p[2] - q[2]));
    const double gp = bidiscGauge(std::fabs(p[0]), std::fabs(p[1]), std::fabs(p[2]), a, b);
    const double gq = bidiscGauge(std::fabs(q[0]), std::fabs(q[1]), std::fabs(q[2]), a, b);
    worst = std::max(worst, std::fabs(gp - gq) / d);
  }
  EXPECT_LE(worst, 1 + 1e-6);
  EXPECT_GT(worst, 0.9);  // and not a trivially flat function
}

// Random sums of 2–6 segments and discs on two axes (random pair, sizes, signs, placements, a
// common random rotation in 2 of 3): the closed form against the certified search of
// (one-axis union of the first k − 1) ⊕ (the second axis's disc by its own formula), 250
// points per sum.
TEST(MinkowskiBidisc, RandomTwoAxisSumsAgreeInSignWithTheCertifiedSearch) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(0, 1);
  const double band = 0.03, tol = 4e-3;
  int compared = 0, sums = 0;
  PointEvaluator pe;
  for (int trial = 0; trial < 40; ++trial) {
    const int k = 2 + trial % 5;
    const int ax1 = trial % 3, ax2 = (ax1 + 1 + trial / 3 % 2) % 3;
    Mat3 rot = trial % 3 == 0 ? identityRotation() : rotationXYZ(6.28 * u(rng), 6.28 * u(rng), 6.28 * u(rng));
    std::vector<Shape> m;
    // A disc on the first axis, segments or more such discs in random order, and last the disc
    // on the second axis: the searched step adds the second axis to a one-axis union (whose
    // pieces have tight interval bounds, so the search stays quick).
    m.push_back(member(ShapeKind::Disc, ax1, 0.05 + 0.4 * u(rng), rot));
    for (int i = 2; i < k; ++i) {
      const int kind = std::uniform_int_distribution<int>(0, 3)(rng);
      if (kind < 3)
        m.push_back(member(ShapeKind::Segment, kind, (u(rng) < 0.3 ? -1 : 1) * (0.1 + 0.7 * u(rng)), rot));
      else
        m.push_back(member(ShapeKind::Disc, ax1, 0.05 + 0.3 * u(rng), rot));
    }
    std::shuffle(m.begin(), m.end(), rng);
    m.push_back(member(ShapeKind::Disc, ax2, 0.05 + 0.4 * u(rng), rot));
    for (Shape& s : m)
      for (int i = 0; i < 3; ++i) s.pos[i] = 0.3 * (u(rng) - 0.5);
    Sum head, all;
    for (int i = 0; i < k; ++i) {
      ASSERT_TRUE(all.add(m[i]));
      if (i + 1 < k) {
        ASSERT_TRUE(head.add(m[i]));
      }
    }
    Reduction rAll = reduce(all), rHead = reduce(head);
    ASSERT_TRUE(rAll.ok && rHead.ok) << rAll.reason << rHead.reason;
    EXPECT_LE(primitives(rAll).size(), 35u);  // Theorem 5 / §IV.F
    MinkowskiOptions opt;
    opt.tolerance = tol;
    const Shape& last = m.back();
    const double ext = std::fabs(last.size[0]) + 0.1;
    Bounds box{{last.pos[0] - ext, last.pos[1] - ext, last.pos[2] - ext},
               {last.pos[0] + ext, last.pos[1] + ext, last.pos[2] + ext}};
    Expr search = minkowskiSum(unionExpr(rHead), memberExpr(last), 3, box, opt);
    TapePtr tape = Tape::compile(search, 3), exactTape = Tape::compile(unionExpr(rAll), 3);
    Vec3 lo, hi;
    worldBox(rAll, lo, hi);
    int here = 0;
    for (int tries = 0; here < 250 && tries < 5000; ++tries) {
      Vec3 p;
      for (int i = 0; i < 3; ++i) p[i] = lo[i] - 0.2 + (hi[i] - lo[i] + 0.4) * u(rng);
      const double exact = unionValue(rAll, p);
      ASSERT_NEAR(pe.eval(*exactTape, p.data()), exact, 1e-12);
      if (std::fabs(exact) < band) continue;
      const double s = pe.eval(*tape, p.data());
      ASSERT_EQ(exact > 0, s >= -2 * tol) << "sum " << all.describe() << " at (" << p[0] << ", " << p[1] << ", "
                                          << p[2] << "): exact " << exact << ", search " << s;
      ++here;
    }
    compared += here;
    ++sums;
  }
  EXPECT_GE(compared, 10000);
  EXPECT_EQ(sums, 40);
}

// The ray-tracer form (4 blocks, 16 cylinders, 8 bicircles; bicircle + 2 cylinders alone) holds
// exactly the points where the closed form is >= 0.
TEST(MinkowskiBidisc, PrimitivesAreTheSum) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  const double L[4][3] = {{0, 0, 0}, {1.2, 0.7, 0.5}, {0.3, 0, 0.9}, {0.2, 0.1, 0.05}};
  for (int trial = 0; trial < 12; ++trial) {
    const int ax1 = trial % 3, ax2 = (ax1 + 1 + trial / 3 % 2) % 3;
    Sum s;
    Shape blk = member(ShapeKind::Block, 0, 0);
    blk.size = {L[trial % 4][0], L[trial % 4][1], L[trial % 4][2]};
    s.add(blk);
    s.add(member(ShapeKind::Disc, ax1, 0.1 + 0.4 * u(rng)));
    s.add(member(ShapeKind::Disc, ax2, 0.1 + 0.4 * u(rng)));
    Reduction r = reduce(s);
    ASSERT_TRUE(r.ok);
    const std::vector<Piece> prims = primitives(r);
    if (trial % 4 == 0) {
      EXPECT_EQ(prims.size(), 3u);  // §IV.B: bidisc = bicircle ∪ 2 cylinders
      EXPECT_EQ(std::count_if(prims.begin(), prims.end(), [](const Piece& p) { return p.kind == PieceKind::Bicircle; }), 1);
    }
    if (trial % 4 == 1) {
      EXPECT_EQ(prims.size(), 28u);
    }
    Vec3 lo, hi;
    worldBox(r, lo, hi);
    int n = 0;
    for (int i = 0; i < 20000 && n < 3000; ++i) {
      Vec3 p;
      for (int c = 0; c < 3; ++c) p[c] = lo[c] - 0.1 + (hi[c] - lo[c] + 0.2) * u(rng);
      const double g = unionValue(r, p);
      if (std::fabs(g) < 1e-6) continue;
      bool held = false;
      for (const Piece& q : prims) held = held || primitiveHolds(q, p);
      ASSERT_EQ(held, g > 0) << s.describe() << " at " << p[0] << " " << p[1] << " " << p[2] << ": " << g;
      ++n;
    }
    EXPECT_EQ(n, 3000);
  }
}

// V(block ⊕ D) for D = xdisc(a) ⊕ ydisc(b) by the projections of D (D is symmetric in the
// coordinate planes): L_x L_y L_z + Σ L_j L_k w_i + Σ L_i A_jk + V(D), widths w = (2b, 2a,
// 2(a + b)), A_yz = πa² + 4ab, A_xz = πb² + 4ab, A_xy = 4ab, V(D) = 2πab(a + b).
TEST(MinkowskiBidisc, VolumeMatchesTheMixedVolumeFormula) {
  const double lx = 0.9, ly = 0.6, lz = 0.4, a = 0.3, b = 0.2;
  const Mat3 rot = rotationXYZ(0.5, -0.2, 0.8);
  Sum s;
  s.add(member(ShapeKind::Segment, 0, lx, rot));
  s.add(member(ShapeKind::Segment, 1, ly, rot));
  s.add(member(ShapeKind::Segment, 2, -lz, rot));
  s.add(member(ShapeKind::Disc, 0, a, rot));
  s.add(member(ShapeKind::Disc, 1, b, rot));
  const double v = lx * ly * lz + ly * lz * 2 * b + lx * lz * 2 * a + lx * ly * 2 * (a + b) +
                   lx * (kPi * a * a + 4 * a * b) + ly * (kPi * b * b + 4 * a * b) + lz * 4 * a * b +
                   2 * kPi * a * b * (a + b);
  EXPECT_NEAR(latticeVolume(reduce(s), 160) / v, 1.0, 4e-3);
  // The bidisc alone: 2πab(a + b) (Fig. 5).
  Sum d;
  d.add(member(ShapeKind::Disc, 2, a, rot));
  d.add(member(ShapeKind::Disc, 0, b, rot));
  EXPECT_NEAR(latticeVolume(reduce(d), 160) / (2 * kPi * a * b * (a + b)), 1.0, 4e-3);
}

// Subtraction chain (eq. 19–21) with a bidisc: a block eroded by a sum is the block moved in by
// the sum's support function (erosionExpr's block case, checked against the search for one-axis
// sums in minkowski_algebra_test.cpp), so here the bidisc sum's support function is checked
// against a brute-force max over its circles' points and its segment's ends; a sphere eroded by
// it has no closed form and is refused.
TEST(MinkowskiBidisc, SupportFunctionForErosionIsTheBruteForceMax) {
  const Mat3 rot = rotationXYZ(0.4, 0.2, -0.3);
  Sum sub;
  sub.add(member(ShapeKind::Disc, 0, 0.3, rot));
  sub.add(member(ShapeKind::Disc, 2, 0.2, rot));
  sub.add(member(ShapeKind::Segment, 1, 0.5, rot));
  Reduction r = reduce(sub);
  ASSERT_TRUE(r.ok);
  auto axis = [&](int a) { return Vec3{rot[a], rot[3 + a], rot[6 + a]}; };
  const Vec3 ex = axis(0), ey = axis(1), ez = axis(2);
  std::mt19937 rng(17);
  std::normal_distribution<double> g(0, 1);
  for (int trial = 0; trial < 40; ++trial) {
    Vec3 n{g(rng), g(rng), g(rng)};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& v : n) v /= len;
    auto dot = [&](const Vec3& a) { return a[0] * n[0] + a[1] * n[1] + a[2] * n[2]; };
    // xdisc(0.3) spans ey, ez; zdisc(0.2) spans ex, ey; yline(0.5) from 0 to 0.5 ey.
    double h1 = -INFINITY, h2 = -INFINITY;
    for (int k = 0; k < 100000; ++k) {
      const double t = 2 * kPi * k / 100000;
      h1 = std::max(h1, 0.3 * (std::cos(t) * dot(ey) + std::sin(t) * dot(ez)));
      h2 = std::max(h2, 0.2 * (std::cos(t) * dot(ex) + std::sin(t) * dot(ey)));
    }
    const double brute = h1 + h2 + std::max(0.0, 0.5 * dot(ey)) + dot(sub.offset);
    EXPECT_NEAR(supportValue(r, n), brute, 1e-8);
  }
  const std::vector<Expr> xs{Expr::x(0), Expr::x(1), Expr::x(2)};
  Sum c0;
  Shape blk = member(ShapeKind::Block, 0, 0);
  blk.size = {3, 2.5, 2};
  c0.add(blk);
  Expr out;
  EXPECT_TRUE(erosionExpr(c0, r, xs, &out, nullptr));
  Sum ball;
  ball.add(member(ShapeKind::Sphere, 0, 1.6));
  std::string why;
  EXPECT_FALSE(erosionExpr(ball, r, xs, &out, &why));
  EXPECT_NE(why.find("bidisc"), std::string::npos);
}

}  // namespace
}  // namespace frep::minkowski
