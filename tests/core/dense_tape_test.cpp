// DenseTape (frep/expressions/dense_tape.h) and its evaluators (frep/evaluators/dense_eval.h):
// the interval pass gives IntervalEvaluator's bounds bit for bit, a tape simplified by a box's
// choices gives the full tape's double values bit for bit at every point of the box, in few
// registers, and slices of arithmetic-only models (the dense path of evaluatePlane) are the
// every-pixel values, with the double signs in float.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "frep/evaluators/dense_eval.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/dense_tape.h"
#include "frep/sampling/plane.h"

using namespace frep;

namespace {

// CSG of spheres, boxes and planes with only the dense subset's ops (+ - * neg abs sqrt square
// min max): unions, intersections, differences, shells and offsets.
Expr arithmeticCsg(std::mt19937_64& rng, int depth) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  if (depth == 0 || rng() % 6 == 0) {
    const double cx = u(rng), cy = u(rng), cz = u(rng), r = 0.2 + 0.3 * std::fabs(u(rng));
    switch (rng() % 3) {
      case 0:
        return sqrt(square(x - cx) + square(y - cy) + square(z - cz)) - r;
      case 1:
        return max(max(abs(x - cx), abs(y - cy)), abs(z - cz)) - r;
      default:
        return 0.3 * u(rng) - u(rng) * x - u(rng) * y - u(rng) * z;
    }
  }
  const Expr a = arithmeticCsg(rng, depth - 1), b = arithmeticCsg(rng, depth - 1);
  switch (rng() % 5) {
    case 0:
      return max(a, b);
    case 1:
      return min(a, b);
    case 2:
      return min(a, -b);
    case 3:
      return abs(a) - 0.05;
    default:
      return (a * b) - 0.01;
  }
}

uint64_t bits(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace

TEST(DenseTape, SimplifiedTapesGiveTheFullTapesBitsInTheirBox) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0), w(0.01, 0.8), t(0.0, 1.0);
  size_t decidedBoxes = 0;
  for (int m = 0; m < 40; ++m) {
    TapePtr tape = Tape::compile(arithmeticCsg(rng, 6), 3);
    ASSERT_TRUE(DenseTape::supports(*tape));
    DenseTape root;
    root.assign(*tape);
    DenseIntervalEvaluator di;
    di.bind(*tape);
    IntervalEvaluator ref;
    DenseSimplifier simp;
    DenseBatchEvaluator<double> db;
    db.bind(*tape);
    BatchEvaluator<double> full;
    std::vector<uint8_t> choices(root.size());
    for (int k = 0; k < 20; ++k) {
      Interval box[3];
      for (auto& b : box) {
        const double c = u(rng), h = w(rng);
        b = Interval(c - h, c + h);
      }
      uint32_t decided = 0;
      const Interval got = di.eval(root, box, choices.data(), &decided);
      const Interval want = ref.eval(*tape, box);
      EXPECT_EQ(bits(got.lo), bits(want.lo));
      EXPECT_EQ(bits(got.hi), bits(want.hi));
      DenseTape pruned;
      simp.simplify(root, choices.data(), pruned);
      if (decided) {
        ++decidedBoxes;
        EXPECT_LT(pruned.size(), root.size());
      }
      EXPECT_LE(pruned.numRegs, root.numRegs);
      // A twice-simplified tape (a sub-box) stays exact too.
      Interval sub[3];
      for (int i = 0; i < 3; ++i) sub[i] = Interval(box[i].lo, box[i].mid());
      std::vector<uint8_t> subChoices(pruned.size());
      di.eval(pruned, sub, subChoices.data(), &decided);
      DenseTape twice;
      simp.simplify(pruned, subChoices.data(), twice);
      for (const DenseTape* dt : {&pruned, &twice}) {
        const Interval* b = dt == &pruned ? box : sub;
        const size_t n = 64;
        db.reserve(*dt);
        full.reserve(*tape);
        for (uint32_t v = 0; v < 3; ++v)
          for (size_t i = 0; i < n; ++i) {
            const double p = b[v].lo + t(rng) * b[v].width();
            db.in(v)[i] = p;
            full.in(v)[i] = p;
          }
        const double* f = full.eval(*tape, n);
        const double* g = db.eval(*dt, n);
        for (size_t i = 0; i < n; ++i) ASSERT_EQ(bits(f[i]), bits(g[i])) << "model " << m << " box " << k;
      }
    }
  }
  EXPECT_GT(decidedBoxes, 100u);
}

// simplify4 (the four boxes of one eval4 pass at once, each output in a register of its own)
// keeps what simplify keeps, without its copies: the full tape's bits at points of each box, for
// every subset of the boxes, and again on its own output over sub-boxes.
TEST(DenseTape, FourBoxSimplificationsAreTheOneBoxOnes) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-2.0, 2.0), w(0.01, 0.8), t(0.0, 1.0);
  size_t compared = 0;
  for (int m = 0; m < 30; ++m) {
    TapePtr tape = Tape::compile(arithmeticCsg(rng, 6), 3);
    DenseTape root;
    root.assign(*tape);
    DenseIntervalEvaluator di;
    di.bind(*tape);
    DenseSimplifier four, one;
    DenseBatchEvaluator<double> db;
    db.bind(*tape);
    BatchEvaluator<double> full;
    full.reserve(*tape);
    for (int k = 0; k < 10; ++k) {
      // Four sibling boxes of a random box, then four of the first one's (its tape simplified).
      Interval parent[3];
      for (auto& b : parent) {
        const double c = u(rng), h = w(rng);
        b = Interval(c - h, c + h);
      }
      const DenseTape* tapeOf = &root;
      DenseTape level[2][4];
      for (int depth = 0; depth < 2; ++depth) {
        Interval boxes[12];
        for (int j = 0; j < 4; ++j) {
          boxes[j * 3 + 0] = j & 1 ? Interval(parent[0].mid(), parent[0].hi) : Interval(parent[0].lo, parent[0].mid());
          boxes[j * 3 + 1] = j & 2 ? Interval(parent[1].mid(), parent[1].hi) : Interval(parent[1].lo, parent[1].mid());
          boxes[j * 3 + 2] = parent[2];
        }
        std::vector<uint8_t> choices(4 * tapeOf->size());
        uint32_t decided[4];
        Interval out[4];
        di.eval4(*tapeOf, boxes, choices.data(), decided, out);
        const unsigned wanted = depth == 0 ? 15u : unsigned(rng() % 16);
        DenseTape* bufs[4] = {&level[depth][0], &level[depth][1], &level[depth][2], &level[depth][3]};
        four.simplify4(*tapeOf, choices.data(), wanted, bufs);
        for (int j = 0; j < 4; ++j) {
          if (!((wanted >> j) & 1u)) continue;
          DenseTape single;
          one.simplify(*tapeOf, choices.data() + j, single, 4);
          EXPECT_LE(level[depth][j].size(), single.size());
          const size_t n = 64;
          db.reserve(level[depth][j]);
          for (uint32_t v = 0; v < 3; ++v)
            for (size_t i = 0; i < n; ++i) {
              const double p = boxes[j * 3 + v].lo + t(rng) * boxes[j * 3 + v].width();
              db.in(v)[i] = p;
              full.in(v)[i] = p;
            }
          const double* f = full.eval(*tape, n);
          const double* g = db.eval(level[depth][j], n);
          for (size_t i = 0; i < n; ++i)
            ASSERT_EQ(bits(f[i]), bits(g[i])) << "model " << m << " box " << k << " depth " << depth;
          ++compared;
        }
        for (int i = 0; i < 3; ++i) parent[i] = boxes[i];
        tapeOf = &level[0][0];
      }
    }
  }
  EXPECT_GT(compared, 1000u);
}

TEST(DenseTape, SimplifiedTapeUsesFewRegisters) {
  // 64 spheres: near one of them the tape is that sphere, whatever register the root gave it.
  Expr e = Expr(1e9);
  for (int i = 0; i < 64; ++i) {
    const double a = 2 * M_PI * i / 64;
    e = min(e, sqrt(square(Expr::x(0) - 1.5 * std::cos(a)) + square(Expr::x(1) - 1.5 * std::sin(a))) - 0.1);
  }
  TapePtr tape = Tape::compile(e, 2);
  DenseTape root;
  root.assign(*tape);
  DenseIntervalEvaluator di;
  di.bind(*tape);
  std::vector<uint8_t> choices(root.size());
  const Interval box[2] = {Interval(1.45, 1.55), Interval(-0.05, 0.05)};
  uint32_t decided = 0;
  di.eval(root, box, choices.data(), &decided);
  DenseTape pruned;
  DenseSimplifier().simplify(root, choices.data(), pruned);
  EXPECT_LE(pruned.size(), 8u);  // (x - c)^2 + (y - s)^2, sqrt, - r: a copy at most
  EXPECT_LE(pruned.numRegs, pruned.firstTemp() + 3);
}

TEST(DenseTape, SlicesOfArithmeticModelsAreEveryPixelsValues) {
  std::mt19937_64 rng(5);
  for (int m = 0; m < 6; ++m) {
    TapePtr tape = Tape::compile(arithmeticCsg(rng, 6), 3);
    PlaneLattice l;
    l.normal = 2, l.at = 0.1;
    l.origin[0] = -2.0, l.origin[1] = -1.9;
    l.width = 300, l.height = 211;
    l.step = 3.9 / 299.0;
    std::vector<double> ref(size_t(l.width) * size_t(l.height));
    PointEvaluator pe;
    for (int r = 0; r < l.height; ++r)
      for (int c = 0; c < l.width; ++c) {
        const double x[3] = {l.origin[0] + c * l.step, l.origin[1] + (l.height - 1 - r) * l.step, l.at};
        ref[size_t(r) * size_t(l.width) + size_t(c)] = pe.eval(*tape, x);
      }
    for (int mode = 0; mode < 3; ++mode) {
      PlaneOptions o;
      o.signOnly = mode > 0;
      o.floatSigns = mode == 2;
      o.threads = 1 + m % 2;
      const std::vector<double> got = evaluatePlane(tape, l, o);
      size_t wrong = 0;
      for (size_t i = 0; i < ref.size(); ++i) {
        if (mode == 0) wrong += bits(ref[i]) != bits(got[i]);
        else wrong += (ref[i] >= 0) != (got[i] >= 0) || std::isnan(ref[i]) != std::isnan(got[i]);
      }
      EXPECT_EQ(wrong, 0u) << "model " << m << " mode " << mode;
    }
  }
}

TEST(DenseTape, FourBoxesAtOnceAreFourSingleBoxes) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-2.0, 2.0), w(0.0, 0.8);
  size_t lanes = 0, decided = 0;
  for (int m = 0; m < 30; ++m) {
    TapePtr tape = Tape::compile(arithmeticCsg(rng, 6), 3);
    DenseTape root;
    root.assign(*tape);
    DenseIntervalEvaluator di;
    di.bind(*tape);
    std::vector<uint8_t> one(root.size()), four(4 * root.size());
    for (int k = 0; k < 20; ++k) {
      Interval boxes[12];
      for (auto& b : boxes) {
        const double c = u(rng), h = w(rng);
        b = Interval(c - h, c + h);
      }
      // Unbounded and point boxes too: lanes that take the lane-by-lane path (applyOp).
      if (k % 5 == 0) boxes[rng() % 12].lo = -INFINITY;
      if (k % 7 == 0) boxes[rng() % 12] = Interval(0.25);
      if (k % 3 == 0) boxes[rng() % 12] = Interval(-0.0, 0.0);  // zeros: the outward steps' edge
      uint32_t d4[4];
      Interval out4[4];
      di.eval4(root, boxes, four.data(), d4, out4);
      for (int j = 0; j < 4; ++j) {
        uint32_t d1 = 0;
        const Interval r = di.eval(root, boxes + 3 * j, one.data(), &d1);
        EXPECT_EQ(bits(r.lo), bits(out4[j].lo));
        EXPECT_EQ(bits(r.hi), bits(out4[j].hi));
        EXPECT_EQ(d1, d4[j]);
        for (size_t i = 0; i < root.size(); ++i) {
          if (root.code[i].op == Op::Min || root.code[i].op == Op::Max) {
            ASSERT_EQ(one[i], four[4 * i + size_t(j)]);
          }
        }
        ++lanes;
        decided += d1 > 0;
      }
    }
  }
  EXPECT_GT(decided, lanes / 4);
}

TEST(DenseTape, OneSimplifierAcrossRootsIsAFreshOne) {
  // The simplifier enters a root's constants once; roots with more or fewer constants in turn
  // must still give what a fresh simplifier gives.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-2.0, 2.0), w(0.01, 0.8);
  DenseSimplifier shared;
  size_t checked = 0;
  for (int m = 0; m < 30; ++m) {
    TapePtr tape = Tape::compile(arithmeticCsg(rng, 2 + m % 5), 3);
    DenseTape root;
    root.assign(*tape);
    DenseIntervalEvaluator di;
    di.bind(*tape);
    std::vector<uint8_t> choices(root.size());
    Interval box[3];
    for (auto& b : box) {
      const double c = u(rng), h = w(rng);
      b = Interval(c - h, c + h);
    }
    uint32_t decided = 0;
    di.eval(root, box, choices.data(), &decided);
    DenseTape a, b;
    shared.simplify(root, choices.data(), a);
    DenseSimplifier().simplify(root, choices.data(), b);
    ASSERT_EQ(a.size(), b.size()) << "model " << m;
    EXPECT_EQ(a.numRegs, b.numRegs);
    EXPECT_EQ(a.result, b.result);
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a.code[k].op, b.code[k].op);
      EXPECT_EQ(a.code[k].out, b.code[k].out);
      EXPECT_EQ(a.code[k].a, b.code[k].a);
      EXPECT_EQ(a.code[k].b, b.code[k].b);
    }
    checked += a.size();
  }
  EXPECT_GT(checked, 100u);
}

TEST(DenseTape, SlicesOfEverySizeAreEveryPixelsValues) {
  // From one pixel to images the planner splits twice above the top tiles (256 pixels),
  // square or not, through leaf-sized images that skip the tile passes.
  std::mt19937_64 rng(17);
  const int sizes[][2] = {{1, 1}, {5, 3}, {16, 16}, {17, 40}, {257, 3}, {520, 700}, {1030, 90}};
  for (const auto& s : sizes) {
    TapePtr tape = Tape::compile(arithmeticCsg(rng, 5), 3);
    PlaneLattice l;
    l.normal = 2, l.at = -0.2;
    l.origin[0] = -1.9, l.origin[1] = -2.0;
    l.width = s[0], l.height = s[1];
    l.step = 3.9 / double(std::max(s[0], s[1]));
    std::vector<double> ref(size_t(l.width) * size_t(l.height));
    BatchEvaluator<double> be;
    be.reserve(*tape);
    for (int r = 0; r < l.height; ++r)
      for (int c0 = 0; c0 < l.width; c0 += int(BatchEvaluator<double>::kBatch)) {
        const int n = std::min(int(BatchEvaluator<double>::kBatch), l.width - c0);
        for (int k = 0; k < n; ++k) {
          be.in(0)[k] = l.origin[0] + double(c0 + k) * l.step;
          be.in(1)[k] = l.origin[1] + double(l.height - 1 - r) * l.step;
          be.in(2)[k] = l.at;
        }
        const double* f = be.eval(*tape, size_t(n));
        std::copy(f, f + n, ref.begin() + long(size_t(r) * size_t(l.width) + size_t(c0)));
      }
    for (int mode = 0; mode < 3; ++mode) {
      PlaneOptions o;
      o.signOnly = mode > 0;
      o.floatSigns = mode == 2;
      o.threads = 1 + mode % 2;
      const std::vector<double> got = evaluatePlane(tape, l, o);
      size_t wrong = 0;
      for (size_t i = 0; i < ref.size(); ++i) {
        if (mode == 0) wrong += bits(ref[i]) != bits(got[i]);
        else wrong += (ref[i] >= 0) != (got[i] >= 0) || std::isnan(ref[i]) != std::isnan(got[i]);
      }
      EXPECT_EQ(wrong, 0u) << s[0] << " x " << s[1] << " mode " << mode;
    }
  }
}
