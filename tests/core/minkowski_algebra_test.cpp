// Roerdink's exact Minkowski algebra (core/src/minkowski_algebra): sign agreement with the
// certified extremum search on random sums, volumes against Steiner-type formulas, the paper's
// primitive counts, and subtraction chains against the search.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "frep/extremum/extremum.h"
#include "frep/minkowski_algebra/reduction.h"
#include "minkowski_test_shapes.h"

namespace frep::minkowski {
namespace {

using namespace test_shapes;

Bounds memberBox(const Shape& s, double pad) {
  double ext = std::fabs(s.size[0]) + pad;
  Bounds b;
  for (int i = 0; i < 3; ++i) {
    b.lo.push_back(s.pos[i] - ext);
    b.hi.push_back(s.pos[i] + ext);
  }
  return b;
}

// discAxis: −1 no discs, 0..2 discs on that axis only, kAnyAxis discs on random axes.
constexpr int kAnyAxis = 3;
Shape randomMember(std::mt19937& rng, int discAxis, const Mat3& rot, int kind = -1) {
  std::uniform_real_distribution<double> u(0, 1);
  Shape s;
  s.rot = rot;
  for (int i = 0; i < 3; ++i) s.pos[i] = 0.3 * (u(rng) - 0.5);
  if (kind < 0) kind = std::uniform_int_distribution<int>(0, discAxis >= 0 ? 4 : 3)(rng);
  if (discAxis == kAnyAxis) discAxis = std::uniform_int_distribution<int>(0, 2)(rng);
  if (kind < 3) {
    s.kind = ShapeKind::Segment;
    s.axis = kind;
    s.size[0] = (u(rng) < 0.3 ? -1 : 1) * (0.1 + 0.7 * u(rng));
  } else if (kind == 3) {
    s.kind = ShapeKind::Sphere;
    s.size[0] = 0.05 + 0.3 * u(rng);
  } else {
    s.kind = ShapeKind::Disc;
    s.axis = discAxis;
    s.size[0] = 0.05 + 0.4 * u(rng);
  }
  return s;
}

// For random sums C1 ⊕ … ⊕ Ck (k = 2..6, random axes, sizes, placements and a common random
// rotation), the exact union of the whole sum against the certified search of
// (exact union of C1..C(k−1)) ⊕ Ck, Ck given by its independent formula: one 3D B&B per point.
// Every third sum has discs on random axes, its first two on different axes, so the
// bicircle-sphere, tricircle and tricircle-sphere cases (the convex-projection field) are drawn.
TEST(MinkowskiAlgebra, RandomSumsAgreeInSignWithTheCertifiedSearch) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(0, 1);
  const double band = 0.03, tol = 4e-3;
  int compared = 0, sums = 0, discSums = 0;
  PointEvaluator pe;
  for (int trial = 0; trial < 75; ++trial) {
    const int k = 2 + trial % 5;
    const bool anyAxes = trial % 3 == 2;
    const int discAxis = anyAxes ? kAnyAxis : std::uniform_int_distribution<int>(-1, 2)(rng);
    Mat3 rot = trial % 3 == 0 ? identityRotation()
                              : rotationXYZ(6.28 * u(rng), 6.28 * u(rng), 6.28 * u(rng));
    std::vector<Shape> m;
    for (int i = 0; i < k; ++i) m.push_back(randomMember(rng, discAxis, rot, anyAxes && i < 2 ? 4 : -1));
    if (anyAxes) m[1].axis = (m[0].axis + 1 + trial % 2) % 3;
    Sum head, all;
    for (int i = 0; i < k; ++i) {
      ASSERT_TRUE(all.add(m[i]));
      if (i + 1 < k) {
        ASSERT_TRUE(head.add(m[i]));
      }
    }
    Reduction rAll = reduce(all), rHead = reduce(head);
    ASSERT_TRUE(rAll.ok && rHead.ok) << rAll.reason;
    EXPECT_LE(primitives(rAll).size(), 35u);  // Theorem 5 / §IV.F
    discSums += rAll.count(PieceKind::DiscSum);
    MinkowskiOptions opt;
    opt.tolerance = tol;
    Expr search = minkowskiSum(unionExpr(rHead), memberExpr(m.back()), 3, memberBox(m.back(), 0.1), opt);
    TapePtr tape = Tape::compile(search, 3);
    Vec3 lo, hi;
    worldBox(rAll, lo, hi);
    int here = 0;
    for (int tries = 0; here < 180 && tries < 5000; ++tries) {
      Vec3 p;
      for (int i = 0; i < 3; ++i) p[i] = lo[i] - 0.2 + (hi[i] - lo[i] + 0.4) * u(rng);
      const double exact = unionValue(rAll, p);
      if (std::fabs(exact) < band) continue;
      const double s = pe.eval(*tape, p.data());
      const bool inExact = exact > 0, inSearch = s >= -2 * tol;
      ASSERT_EQ(inExact, inSearch) << "sum " << all.describe() << " at (" << p[0] << ", " << p[1] << ", "
                                   << p[2] << "): exact " << exact << ", search " << s;
      ++here;
    }
    compared += here;
    ++sums;
  }
  EXPECT_GE(compared, 10000);
  EXPECT_EQ(sums, 75);
  EXPECT_GE(discSums, 10);  // bicircle-sphere / tricircle(-sphere) sums among them (12)
}

// With a sphere and at most one disc axis the sum's field is one closed form (the discus distance at the
// excess over the block); it equals the union of the ray-tracer pieces' SDFs outside (both are
// the exact distance) and has its sign everywhere.
TEST(MinkowskiAlgebra, ClosedFormIsThePiecesUnion) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(0, 1);
  PointEvaluator pe;
  int outside = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int discAxis = std::uniform_int_distribution<int>(-1, 2)(rng);
    const Mat3 rot = rotationXYZ(6.28 * u(rng), 6.28 * u(rng), 6.28 * u(rng));
    Sum sum;
    for (int i = 0; i < 2 + trial % 4; ++i) ASSERT_TRUE(sum.add(randomMember(rng, discAxis, rot)));
    const Reduction r = reduce(sum);
    TapePtr closed = Tape::compile(unionExpr(r), 3),
            pieces = Tape::compile(piecesUnionExpr(r, {Expr::x(0), Expr::x(1), Expr::x(2)}), 3);
    Vec3 lo, hi;
    worldBox(r, lo, hi);
    for (int t = 0; t < 300; ++t) {
      double p[3];
      for (int i = 0; i < 3; ++i) p[i] = lo[i] - 0.2 + (hi[i] - lo[i] + 0.4) * u(rng);
      const double a = pe.eval(*closed, p), b = pe.eval(*pieces, p);
      if (std::fabs(b) < 1e-9) continue;
      ASSERT_EQ(a > 0, b > 0) << sum.describe() << " at " << p[0] << " " << p[1] << " " << p[2] << ": " << a << " vs " << b;
      if (b < 0) {
        ASSERT_NEAR(a, b, 1e-12) << sum.describe();
        ++outside;
      }
    }
  }
  EXPECT_GT(outside, 5000);
}

// The lower-dimensional members alone: minus the distance, 0 on the set.
TEST(MinkowskiAlgebra, MembersAloneAreMinusTheirDistance) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 30; ++trial) {
    Mat3 rot = rotationXYZ(3 * u(rng), 3 * u(rng), 3 * u(rng));
    Shape s = randomMember(rng, trial % 3, rot);
    TapePtr t = Tape::compile(memberExpr(s), 3);
    Reduction r = reduce(sumOf(s));
    ASSERT_TRUE(r.ok);
    PointEvaluator pe;
    for (int i = 0; i < 50; ++i) {
      Vec3 p{u(rng), u(rng), u(rng)};
      EXPECT_NEAR(unionValue(r, p), pe.eval(*t, p.data()), 1e-9) << s.describe();
    }
  }
}

TEST(MinkowskiAlgebra, VolumesMatchSteinerFormulas) {
  const Mat3 rot = rotationXYZ(0.3, -0.7, 1.1);
  const double lx = 1.2, ly = 0.8, lz = 0.5, r = 0.3, s = 0.2;
  // block ⊕ sphere: V + S s + M s² + 4/3 π s³ with M = π (lx + ly + lz).
  Sum bs;
  bs.add(member(ShapeKind::Segment, 0, lx, rot));
  bs.add(member(ShapeKind::Segment, 1, -ly, rot));
  bs.add(member(ShapeKind::Segment, 2, lz, rot));
  bs.add(member(ShapeKind::Sphere, 0, s));
  const double vbs = lx * ly * lz + 2 * s * (lx * ly + ly * lz + lx * lz) + kPi * s * s * (lx + ly + lz) +
                     4.0 / 3 * kPi * s * s * s;
  EXPECT_NEAR(latticeVolume(reduce(bs), 160) / vbs, 1.0, 4e-3);
  // block ⊕ zdisc ⊕ sphere: Q = (rect ⊕ disc r) × [0, lz], V(Q ⊕ sB) = V + A s + M s² + 4/3 π s³,
  // A = 2 A2 + P lz, M = π lz + π P / 2 (curved side π lz, two rims of exterior angle π/2).
  Sum bds = bs;
  bds.add(member(ShapeKind::Disc, 2, r, rot));
  const double a2 = lx * ly + 2 * r * (lx + ly) + kPi * r * r, per = 2 * (lx + ly) + 2 * kPi * r;
  const double vbds = lz * a2 + s * (2 * a2 + per * lz) + s * s * (kPi * lz + kPi * per / 2) +
                      4.0 / 3 * kPi * s * s * s;
  EXPECT_NEAR(latticeVolume(reduce(bds), 160) / vbds, 1.0, 4e-3);
  // Segments and a disc only: xline ⊕ yline ⊕ zline ⊕ zdisc = (rect ⊕ disc) × lz; xline ⊕ xdisc
  // = cylinder (§IV.D's example, one primitive).
  Sum sd;
  sd.add(member(ShapeKind::Segment, 0, lx, rot));
  sd.add(member(ShapeKind::Segment, 1, ly, rot));
  sd.add(member(ShapeKind::Segment, 2, lz, rot));
  sd.add(member(ShapeKind::Disc, 2, r, rot));
  EXPECT_NEAR(latticeVolume(reduce(sd), 160) / (lz * a2), 1.0, 4e-3);
  Sum cyl;
  cyl.add(member(ShapeKind::Segment, 0, lx, rot));
  cyl.add(member(ShapeKind::Disc, 0, r, rot));
  Reduction rc = reduce(cyl);
  EXPECT_EQ(rc.pieces.size(), 1u);
  EXPECT_NEAR(latticeVolume(rc, 160) / (kPi * r * r * lx), 1.0, 4e-3);
  // Discus (disc ⊕ sphere): Pappus, π r² 2s + 2π r · π s²/2... = 2π r² s + π² r s² + 4/3 π s³.
  Sum ds;
  ds.add(member(ShapeKind::Disc, 1, r, rot));
  ds.add(member(ShapeKind::Sphere, 0, s));
  const double vds = 2 * kPi * r * r * s + kPi * kPi * r * s * s + 4.0 / 3 * kPi * s * s * s;
  EXPECT_NEAR(latticeVolume(reduce(ds), 160) / vds, 1.0, 4e-3);
}

// The paper's counts: block ⊕ zdisc (§IV.B: 2 blocks, 4 cylinders), block ⊕ sphere (App. B: 3
// blocks, 12 cylinders, 8 spheres), discus (torus ∪ cylinder), block ⊕ zdisc ⊕ sphere (§IV.D:
// 8 tori, 8 z-, 4 x-, 4 y-cylinders and blocks: 4 here, 3 in the paper, see reduction.cpp).
TEST(MinkowskiAlgebra, PrimitiveCountsMatchThePaper) {
  Sum blockSum;
  blockSum.add(member(ShapeKind::Segment, 0, 2));
  blockSum.add(member(ShapeKind::Segment, 1, 1.5));
  blockSum.add(member(ShapeKind::Segment, 2, 1));
  EXPECT_EQ(reduce(blockSum).pieces.size(), 1u);
  Sum bz = blockSum;
  bz.add(member(ShapeKind::Disc, 2, 0.3));
  Reduction r1 = reduce(bz);
  EXPECT_EQ(r1.count(PieceKind::Block), 2);
  EXPECT_EQ(r1.count(PieceKind::Cylinder), 4);
  EXPECT_EQ(r1.pieces.size(), 6u);
  Sum bsph = blockSum;
  bsph.add(member(ShapeKind::Sphere, 0, 0.2));
  Reduction r2 = reduce(bsph);
  EXPECT_EQ(r2.count(PieceKind::Block), 3);
  EXPECT_EQ(r2.count(PieceKind::Cylinder), 12);
  EXPECT_EQ(r2.count(PieceKind::Sphere), 8);
  Sum discus;
  discus.add(member(ShapeKind::Disc, 0, 0.5));
  discus.add(member(ShapeKind::Sphere, 0, 0.1));
  Reduction r3 = reduce(discus);
  EXPECT_EQ(r3.count(PieceKind::Torus), 1);
  EXPECT_EQ(r3.count(PieceKind::Cylinder), 1);
  EXPECT_EQ(r3.pieces.size(), 2u);
  Sum all = bz;
  all.add(member(ShapeKind::Sphere, 0, 0.2));
  Reduction r4 = reduce(all);
  EXPECT_EQ(r4.count(PieceKind::Torus), 8);
  EXPECT_EQ(r4.count(PieceKind::Cylinder), 16);
  EXPECT_EQ(r4.count(PieceKind::Block), 4);
  EXPECT_EQ(r4.pieces.size(), 28u);  // the paper's 27 + the fourth block
  // Each of the 4 blocks is needed: a point of the sum that only it holds (the witnesses of
  // reduction.cpp's argument, for this large block).
  const double lx = 2, ly = 1.5, lz = 1, r = 0.3, s = 0.2, e = 0.001;
  const Vec3 witnesses[4] = {{-0.9 * r, ly / 2, -s + e}, {lx / 2, -0.9 * r, -s + e},
                             {-r - s + e, ly / 2, lz / 2}, {lx / 2, -r - s + e, lz / 2}};
  for (const Vec3& w : witnesses) {
    ASSERT_GT(unionValue(r4, w), 0);
    int holders = 0;
    for (const Piece& p : r4.pieces) holders += primitiveHolds(p, w);  // identity frame: local = world
    EXPECT_EQ(holders, 1) << w[0] << " " << w[1] << " " << w[2];
  }
  // Two disc axes: the closed-form bidisc (minkowski_bidisc_test.cpp).
  Sum bi;
  bi.add(member(ShapeKind::Disc, 0, 0.5));
  bi.add(member(ShapeKind::Disc, 1, 0.5));
  EXPECT_TRUE(reduce(bi).ok);
  EXPECT_EQ(primitives(reduce(bi)).size(), 3u);
}

// §IV.D's ungrouped path for block ⊕ zdisc ⊕ sphere: reduce block ⊕ zdisc (2 blocks, 4
// cylinders), then each piece ⊕ sphere (a block: 3 blocks, 12 cylinders, 8 spheres; a
// cylinder, zline ⊕ zdisc ⊕ sphere: 2 tori, 2 cylinders) — the paper's 62 — against the grouped
// 28, which holds the same points.
TEST(MinkowskiAlgebra, UngroupedReductionHasThePapers62) {
  const double lx = 2, ly = 1.5, lz = 1, r = 0.3, s = 0.2;
  Sum bz;
  bz.add(member(ShapeKind::Segment, 0, lx));
  bz.add(member(ShapeKind::Segment, 1, ly));
  bz.add(member(ShapeKind::Segment, 2, lz));
  bz.add(member(ShapeKind::Disc, 2, r));
  std::vector<Reduction> parts;
  int spheres = 0, blocks = 0, tori = 0, cylinders = 0;
  for (const Piece& p : reduce(bz).pieces) {
    Shape m;  // the piece as a basic-set sum: a block, or zline ⊕ zdisc at its base
    Sum part;
    if (p.kind == PieceKind::Block) {
      m.kind = ShapeKind::Block;
      m.pos = p.lo;
      for (int i = 0; i < 3; ++i) m.size[i] = p.hi[i] - p.lo[i];
      part.add(m);
    } else {
      ASSERT_EQ(p.kind, PieceKind::Cylinder);
      m = member(ShapeKind::Segment, p.axis, p.length);
      m.pos = p.base;
      part.add(m);
      part.add(member(ShapeKind::Disc, p.axis, p.radius));
    }
    part.add(member(ShapeKind::Sphere, 0, s));
    parts.push_back(reduce(part));
    ASSERT_TRUE(parts.back().ok);
    spheres += parts.back().count(PieceKind::Sphere);
    blocks += parts.back().count(PieceKind::Block);
    tori += parts.back().count(PieceKind::Torus);
    cylinders += parts.back().count(PieceKind::Cylinder);
  }
  EXPECT_EQ(spheres, 16);
  EXPECT_EQ(blocks, 6);
  EXPECT_EQ(tori, 8);
  EXPECT_EQ(cylinders, 32);
  EXPECT_EQ(spheres + blocks + tori + cylinders, 62);
  Sum all = bz;
  all.add(member(ShapeKind::Sphere, 0, s));
  Reduction grouped = reduce(all);
  EXPECT_EQ(grouped.pieces.size(), 28u);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-0.6, 2.6);
  for (int i = 0; i < 5000; ++i) {
    Vec3 p{u(rng), u(rng) * 0.8, u(rng) * 0.6};
    double ungrouped = -INFINITY;
    for (const Reduction& part : parts) ungrouped = std::max(ungrouped, unionValue(part, p));
    const double g = unionValue(grouped, p);
    if (g <= 0) EXPECT_NEAR(ungrouped, g, 1e-9);  // both minus the distance outside
    else EXPECT_GT(ungrouped, 0);
  }
}

// Subtraction chains (eq. 19–21) against the certified search of the erosion.
TEST(MinkowskiAlgebra, SubtractionChainsAgreeWithTheSearch) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(-1, 1);
  const Mat3 rot = rotationXYZ(0.4, 0.2, -0.3);
  Sum b;  // the eroded block, in its own (identity) frame: 3 x 2.5 x 2 from (-1.5, -1.25, -1)
  Shape blk;
  blk.kind = ShapeKind::Block;
  blk.size = {3, 2.5, 2};
  blk.pos = {-1.5, -1.25, -1};
  b.add(blk);
  Sum ball;
  ball.add(member(ShapeKind::Sphere, 0, 1.6));
  Sum sub;  // xline ⊕ zdisc ⊕ sphere, rotated
  sub.add(member(ShapeKind::Segment, 0, 0.6, rot));
  sub.add(member(ShapeKind::Disc, 2, 0.3, rot));
  sub.add(member(ShapeKind::Sphere, 0, 0.1));
  Reduction r = reduce(sub);
  ASSERT_TRUE(r.ok);
  // The search's B: the exact union of sub (checked against the search above).
  Vec3 lo, hi;
  worldBox(r, lo, hi);
  Bounds bb{{lo[0] - 0.05, lo[1] - 0.05, lo[2] - 0.05}, {hi[0] + 0.05, hi[1] + 0.05, hi[2] + 0.05}};
  const std::vector<Expr> xs{Expr::x(0), Expr::x(1), Expr::x(2)};
  PointEvaluator pe;
  for (const Sum& c0 : {b, ball}) {
    Expr exact;
    ASSERT_TRUE(erosionExpr(c0, r, xs, &exact, nullptr));
    SearchOptions so;
    so.tolerance = 1e-3;
    Expr search = minkowskiDifference(unionExpr(reduce(c0)), unionExpr(r), 3, bb, so);
    TapePtr te = Tape::compile(exact, 3), ts = Tape::compile(search, 3);
    int n = 0;
    for (int i = 0; i < 4000 && n < 600; ++i) {
      Vec3 p{1.6 * u(rng), 1.6 * u(rng), 1.6 * u(rng)};
      double e = pe.eval(*te, p.data());
      if (std::fabs(e) < 0.02) continue;
      double s = pe.eval(*ts, p.data());
      ASSERT_EQ(e > 0, s > 0) << c0.describe() << " at " << p[0] << " " << p[1] << " " << p[2] << ": " << e
                              << " vs " << s;
      ++n;
    }
    EXPECT_GE(n, 600);
  }
}

}  // namespace
}  // namespace frep::minkowski
