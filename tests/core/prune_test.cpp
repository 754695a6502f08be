// Tape pruning by interval evaluation: boxes decide min/max/select choices, the pruned tape is
// shorter and gives the same bits as the full tape everywhere inside the box.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "core/random_csg.h"

using namespace frep;
using frep::testing::randomCsg;
using frep::testing::ringOfSpheres;
using frep::testing::sphere;

namespace {

double randomIn(const Interval& r, std::mt19937_64& rng) {
  double v = r.lo + std::uniform_real_distribution<double>(0.0, 1.0)(rng) * r.width();
  return std::min(r.hi, std::max(r.lo, v));
}

void randomBox(std::mt19937_64& rng, double size, Interval* box) {
  std::uniform_real_distribution<double> u(-2.0, 2.0 - size);
  for (int i = 0; i < 3; ++i) {
    double lo = u(rng);
    box[i] = {lo, lo + size};
  }
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Checks pruned against full at random points of the box with the point and batch evaluators.
void expectSameInside(const Tape& full, const Tape& pruned, const Interval* box, std::mt19937_64& rng) {
  PointEvaluator pe;
  BatchEvaluator<double> bf, bp;
  bf.reserve(full);
  bp.reserve(pruned);
  constexpr int n = 64;
  double pts[n][3];
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < 3; ++i) bf.in(i)[k] = bp.in(i)[k] = pts[k][i] = randomIn(box[i], rng);
  const double* vf = bf.eval(full, n);
  const double* vp = bp.eval(pruned, n);
  for (int k = 0; k < n; ++k) {
    const double f = pe.eval(full, pts[k]);
    ASSERT_TRUE(sameBits(f, pe.eval(pruned, pts[k])));
    ASSERT_TRUE(sameBits(vf[k], vp[k]));
    ASSERT_TRUE(sameBits(f, vf[k]));
  }
}

}  // namespace

TEST(Prune, SphereBoxesClassifyInsideOutsideAmbiguous) {
  TapePtr t = Tape::compile(sphere(0, 0, 0, 1));
  IntervalEvaluator ie;
  Interval inside[3] = {{-0.3, 0.3}, {-0.3, 0.3}, {-0.3, 0.3}};
  Interval outside[3] = {{1.2, 2.0}, {-0.1, 0.1}, {-0.1, 0.1}};
  Interval ambiguous[3] = {{0.9, 1.1}, {-0.1, 0.1}, {-0.1, 0.1}};
  EXPECT_GT(ie.eval(*t, inside).lo, 0.0);
  EXPECT_LT(ie.eval(*t, outside).hi, 0.0);
  Interval r = ie.eval(*t, ambiguous);
  EXPECT_LT(r.lo, 0.0);
  EXPECT_GT(r.hi, 0.0);
  // Tight for a sphere: over the inside box f is in [1 - 3 * 0.09, 1].
  r = ie.eval(*t, inside);
  EXPECT_NEAR(r.lo, 0.73, 1e-9);
  EXPECT_NEAR(r.hi, 1.0, 1e-9);
}

TEST(Prune, DecidedUnionKeepsOneSphere) {
  Expr a = sphere(-1, 0, 0, 0.5), b = sphere(1, 0, 0, 0.5);
  TapePtr t = Tape::compile(max(a, b));
  TapePtr ta = Tape::compile(a);
  IntervalEvaluator ie;
  Interval box[3] = {{-1.1, -0.9}, {-0.1, 0.1}, {-0.1, 0.1}};  // near sphere a only
  ie.eval(*t, box);
  int decided = 0;
  for (size_t i = 0; i < t->size(); ++i)
    if (t->code()[i].op == Op::Max) decided += ie.choices()[i] != Choice::Both;
  EXPECT_EQ(decided, 1);
  TapePtr p = ie.pruned(t);
  EXPECT_EQ(p->size(), ta->size());  // only sphere a's instructions remain
  EXPECT_EQ(p->numChoices(), 0u);
  // Undecided box: nothing pruned, the same tape comes back.
  Interval wide[3] = {{-2, 2}, {-1, 1}, {-1, 1}};
  ie.eval(*t, wide);
  EXPECT_EQ(ie.pruned(t).get(), t.get());
  std::mt19937_64 rng(3);
  expectSameInside(*t, *p, box, rng);
}

TEST(Prune, SelectKeepsTheBranchItsConditionDecides) {
  Expr x = Expr::x(0);
  Expr e = select(gt(x, 0.0), sphere(1, 0, 0, 0.5), sphere(-1, 0, 0, 0.5));
  TapePtr t = Tape::compile(e);
  IntervalEvaluator ie;
  PointEvaluator pe;
  Interval right[3] = {{0.5, 1.5}, {-1, 1}, {-1, 1}};
  ie.eval(*t, right);
  TapePtr p = ie.pruned(t);
  EXPECT_LT(p->size(), t->size());
  double q[3] = {1.0, 0.0, 0.0};
  EXPECT_EQ(pe.eval(*p, q), 0.25);
  Interval left[3] = {{-1.5, -0.5}, {-1, 1}, {-1, 1}};
  ie.eval(*t, left);
  p = ie.pruned(t);
  EXPECT_LT(p->size(), t->size());
  q[0] = -1.0;
  EXPECT_EQ(pe.eval(*p, q), 0.25);
}

TEST(Prune, MinTiesKeepFirstOperandExactly) {
  // Scalar min is `b < a ? b : a`: a tie keeps a, so a may be kept when a.hi == b.lo but b
  // only when b.hi < a.lo. Operand order is canonical (hash), so test both orders.
  Expr x = Expr::x(0);
  TapePtr t = Tape::compile(min(x, Expr(1.0)), 1);
  ASSERT_EQ(t->size(), 1u);
  const bool xFirst = t->code()[0].a == t->varReg(0);
  IntervalEvaluator ie;
  PointEvaluator pe;
  Interval low[1] = {{0.0, 1.0}}, high[1] = {{1.0, 2.0}};
  ie.eval(*t, low);
  EXPECT_EQ(ie.choices()[0], xFirst ? Choice::KeepA : Choice::Both);
  TapePtr p = ie.pruned(t);
  for (double v : {0.0, 0.25, 1.0}) EXPECT_TRUE(sameBits(pe.eval(*t, &v), pe.eval(*p, &v)));
  ie.eval(*t, high);
  EXPECT_EQ(ie.choices()[0], xFirst ? Choice::Both : Choice::KeepA);
  p = ie.pruned(t);
  for (double v : {1.0, 1.5, 2.0}) EXPECT_TRUE(sameBits(pe.eval(*t, &v), pe.eval(*p, &v)));
}

TEST(Prune, RandomCsgPrunedTapesMatchBitForBit) {
  std::mt19937_64 rng(11);
  IntervalEvaluator ie;
  int shrunk = 0, boxes = 0;
  for (int model = 0; model < 200; ++model) {
    TapePtr t = Tape::compile(randomCsg(rng, 5), 3);
    for (int b = 0; b < 10; ++b) {
      Interval box[3];
      randomBox(rng, b % 2 ? 0.05 : 0.4, box);
      ie.eval(*t, box);
      bool decided = false;
      for (Choice c : ie.choices()) decided |= c != Choice::Both;
      TapePtr p = ie.pruned(t);
      ++boxes;
      if (decided) {
        ASSERT_LT(p->size(), t->size());
        ++shrunk;
      } else {
        ASSERT_EQ(p.get(), t.get());
      }
      expectSameInside(*t, *p, box, rng);
      // Pruning again inside a sub-box of the box stays exact.
      Interval sub[3];
      for (int i = 0; i < 3; ++i) sub[i] = {box[i].lo, box[i].mid()};
      ie.eval(*p, sub);
      TapePtr pp = ie.pruned(p);
      EXPECT_LE(pp->size(), p->size());
      expectSameInside(*t, *pp, sub, rng);
    }
  }
  EXPECT_GT(shrunk, boxes / 4);
}

// The figure that matters for sampling: 16 spheres, small boxes near the ring, the pruned
// tape is a small fraction of the full one.
TEST(Prune, SixteenSpheresShrinkOnSmallBoxes) {
  TapePtr t = Tape::compile(ringOfSpheres(16));
  IntervalEvaluator ie;
  std::mt19937_64 rng(5);
  double sumRatio = 0;
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    double ang = std::uniform_real_distribution<double>(0, 6.283185307179586)(rng);
    double cx = 1.5 * std::cos(ang), cy = 1.5 * std::sin(ang);
    Interval box[3] = {{cx - 0.05, cx + 0.05}, {cy - 0.05, cy + 0.05}, {-0.05, 0.05}};
    ie.eval(*t, box);
    TapePtr p = ie.pruned(t);
    sumRatio += double(p->size()) / double(t->size());
    expectSameInside(*t, *p, box, rng);
  }
  const double avg = sumRatio / n;
  std::printf("16 spheres: full tape %zu instrs, average pruned/full %.3f over %d boxes of 0.1^3\n", t->size(),
              avg, n);
  EXPECT_LT(avg, 0.2);
}

// A decided min/max becomes a copy of its kept input; copies are propagated to their readers, so
// a union of spheres decided to one sphere is that sphere's instructions alone, no copy left.
TEST(Prune, DecidedChoicesLeaveNoCopies) {
  TapePtr t = Tape::compile(ringOfSpheres(32), 3);
  IntervalEvaluator ie;
  Interval box[3] = {{1.45, 1.55}, {-0.05, 0.05}, {-0.05, 0.05}};
  ie.eval(*t, box);
  TapePtr p = ie.pruned(t);
  size_t copies = 0;
  for (const Instr& ins : p->code()) copies += ins.op == Op::Copy;
  EXPECT_EQ(copies, 0u);
  TapePtr single = Tape::compile(sphere(1.5, 0.0, 0.0, 0.4), 3);
  EXPECT_LE(p->size(), single->size());
  PointEvaluator pe;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 200; ++i) {
    double x[3] = {randomIn(box[0], rng), randomIn(box[1], rng), randomIn(box[2], rng)};
    const double a = pe.eval(*t, x), b = pe.eval(*p, x);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0);
  }
}
