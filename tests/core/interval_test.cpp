// Interval arithmetic: exact expected ranges on hand-picked cases, per-op soundness against the
// scalar applyOp on random intervals, and soundness of whole random expression DAGs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/evaluators/interval.h"

using namespace frep;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.141592653589793;

bool isEverything(const Interval& r) { return r.lo == -kInf && r.hi == kInf; }

// The soundness contract at one point: a NaN value needs everything(), any other value must lie inside.
::testing::AssertionResult encloses(const Interval& r, double v) {
  if (std::isnan(v) ? isEverything(r) : r.contains(v)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << v << " not in [" << r.lo << ", " << r.hi << "]";
}

// Intervals from several families that hit the edge cases: touching or crossing 0, integers,
// poles and extrema of the trigonometric functions, huge and infinite bounds, points.
Interval randomInterval(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto pick = [&](std::initializer_list<double> v) { return v.begin()[rng() % v.size()]; };
  double a = 0, b = 0;
  switch (rng() % 10) {
    case 0: a = 6 * u(rng) - 3; b = 6 * u(rng) - 3; break;
    case 1: a = 2e3 * u(rng) - 1e3; b = a + 20 * u(rng); break;
    case 2: a = 0.0; b = pick({-1.0, 1.0}) * 3 * u(rng); break;         // touches 0
    case 3: a = std::round(8 * u(rng) - 4); b = a + pick({0.0, 0.5, 1.0, 2.5}); break;  // integers
    case 4: a = pick({kPi / 2, -kPi / 2, kPi, 3 * kPi / 2, 0.0}) + pick({-1e-3, 0.0, 1e-3}); b = a + 1e-3 * u(rng); break;
    case 5: a = 4 * u(rng) - 2; b = a; break;                            // point
    case 6: a = pick({-kInf, -1e300, 1e300, 0.0}); b = 10 * u(rng) - 5; break;
    case 7: a = pick({-1.0, 1.0, -0.5, 0.5}); b = pick({-1.0, 1.0, 2.0, -2.0}); break;
    case 8: a = 1e-3 * u(rng); b = -1e-3 * u(rng); break;                 // tiny around 0
    default: a = 60 * u(rng) - 30; b = 60 * u(rng) - 30; break;
  }
  if (rng() % 16 == 0) b = pick({kInf, -kInf});
  if (a > b) std::swap(a, b);
  return {a, b};
}

double randomPoint(const Interval& r, std::mt19937_64& rng) {
  switch (rng() % 6) {
    case 0: return r.lo == 0.0 && rng() % 2 ? -0.0 : r.lo;  // [0, x] holds -0 as well
    case 1: return r.hi == 0.0 && rng() % 2 ? -0.0 : r.hi;
    default: break;
  }
  double lo = std::isinf(r.lo) ? std::min(-1e6, r.hi) : r.lo;
  double hi = std::isinf(r.hi) ? std::max(1e6, r.lo) : r.hi;
  if (std::isinf(lo) || std::isinf(hi)) return r.lo;  // [inf, inf] or [-inf, -inf]
  double t = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  double v = lo + t * (hi - lo);
  return std::min(hi, std::max(lo, v));
}

}  // namespace

TEST(Interval, ExactRangesOfSimpleOps) {
  Interval r = applyOp(Op::PowI, Interval(-1.0, 2.0), {}, {}, 2);
  EXPECT_EQ(r.lo, 0.0);  // the minimum of x^2 is inside, not at an endpoint
  EXPECT_GE(r.hi, 4.0);
  EXPECT_LT(r.hi, 4.0 + 1e-12);
  r = applyOp(Op::Abs, Interval(-3.0, 2.0));
  EXPECT_EQ(r.lo, 0.0);
  EXPECT_EQ(r.hi, 3.0);
  r = applyOp(Op::Add, Interval(1.0, 2.0), Interval(10.0, 20.0));
  EXPECT_LE(r.lo, 11.0);
  EXPECT_GT(r.lo, 11.0 - 1e-12);
  EXPECT_GE(r.hi, 22.0);
  EXPECT_LT(r.hi, 22.0 + 1e-12);
  EXPECT_EQ(applyOp(Op::Floor, Interval(-1.5, 2.5)).lo, -2.0);
  EXPECT_EQ(applyOp(Op::Floor, Interval(-1.5, 2.5)).hi, 2.0);
  r = applyOp(Op::Sqrt, Interval(-4.0, 4.0));
  EXPECT_EQ(r.lo, 0.0);  // sqrt(x < 0) = 0
  EXPECT_GE(r.hi, 2.0);
  r = applyOp(Op::Log, Interval(-1.0, 1.0));
  EXPECT_LE(r.lo, std::log(kLogFloor));
  EXPECT_GT(r.lo, std::log(kLogFloor) - 1e-9);
}

TEST(Interval, TrigonometricExtremaAndPoles) {
  Interval s = applyOp(Op::Sin, Interval(0.1, 0.2));
  EXPECT_GT(s.lo, 0.09);
  EXPECT_LT(s.hi, 0.2);
  s = applyOp(Op::Sin, Interval(0.0, kPi));
  EXPECT_EQ(s.hi, 1.0);  // contains pi/2
  EXPECT_GT(s.lo, -1e-12);
  s = applyOp(Op::Cos, Interval(3.0, 3.5));
  EXPECT_EQ(s.lo, -1.0);  // contains pi
  EXPECT_LT(s.hi, -0.93);
  s = applyOp(Op::Sin, Interval(-100.0, 100.0));
  EXPECT_EQ(s.lo, -1.0);
  EXPECT_EQ(s.hi, 1.0);
  EXPECT_TRUE(isEverything(applyOp(Op::Tan, Interval(1.5, 1.6))));  // pole at pi/2
  Interval t = applyOp(Op::Tan, Interval(-1.0, 1.0));
  EXPECT_LT(t.hi, 1.56);
  EXPECT_GT(t.lo, -1.56);
  EXPECT_TRUE(isEverything(applyOp(Op::Sin, Interval(0.0, kInf))));  // sin(inf) is NaN
}

TEST(Interval, DivisionPowersAndNaNCases) {
  EXPECT_TRUE(isEverything(applyOp(Op::Div, Interval(1.0), Interval(-1.0, 1.0))));
  EXPECT_TRUE(isEverything(applyOp(Op::Div, Interval(1.0), Interval(0.0, 1.0))));
  Interval q = applyOp(Op::Div, Interval(1.0, 2.0), Interval(4.0, 8.0));
  EXPECT_LE(q.lo, 0.125);
  EXPECT_GE(q.hi, 0.5);
  EXPECT_TRUE(isEverything(applyOp(Op::PowI, Interval(-1.0, 1.0), {}, {}, -1)));
  Interval p = applyOp(Op::PowI, Interval(-2.0, 1.0), {}, {}, -2);  // 1/x^2: [1/4, inf]
  EXPECT_LE(p.lo, 0.25);
  EXPECT_GT(p.lo, 0.24);
  EXPECT_EQ(p.hi, kInf);
  EXPECT_TRUE(isEverything(applyOp(Op::Pow, Interval(-1.0, 2.0), Interval(0.5))));
  EXPECT_TRUE(isEverything(applyOp(Op::Mul, Interval(0.0, 1.0), Interval(1.0, kInf))));  // 0 * inf
  EXPECT_TRUE(isEverything(applyOp(Op::Fmod, Interval(1.0, 2.0), Interval(-1.0, 1.0))));
  EXPECT_TRUE(isEverything(applyOp(Op::Exp, Interval::everything())));   // may be NaN
  Interval m = applyOp(Op::Min, Interval(0.0, 1.0), Interval::everything());  // min(a, NaN) = a
  EXPECT_EQ(m.lo, -kInf);
  EXPECT_EQ(m.hi, 1.0);
  EXPECT_TRUE(isEverything(applyOp(Op::Min, Interval::everything(), Interval(0.0, 1.0))));
}

TEST(Interval, FracFmodAndAtan2Discontinuities) {
  Interval f = applyOp(Op::Frac, Interval(1.25, 1.75));
  EXPECT_EQ(f.lo, 0.25);
  EXPECT_EQ(f.hi, 0.75);
  f = applyOp(Op::Frac, Interval(0.5, 2.5));  // crosses integers
  EXPECT_EQ(f.lo, 0.0);
  EXPECT_GE(f.hi, 0.99);
  f = applyOp(Op::Frac, Interval(-2.5, -0.5));
  EXPECT_LE(f.lo, -0.99);
  EXPECT_EQ(f.hi, 0.0);
  Interval m = applyOp(Op::Fmod, Interval(0.5, 0.7), Interval(1.0, 2.0));
  EXPECT_EQ(m.lo, 0.5);
  EXPECT_EQ(m.hi, 0.7);
  m = applyOp(Op::Fmod, Interval(3.0, 10.0), Interval(2.0));
  EXPECT_EQ(m.lo, 0.0);
  EXPECT_EQ(m.hi, 2.0);
  Interval a = applyOp(Op::Atan2, Interval(-1.0, 1.0), Interval(-2.0, -1.0));  // branch cut
  EXPECT_LE(a.lo, -kPi);
  EXPECT_GE(a.hi, kPi);
  a = applyOp(Op::Atan2, Interval(1.0, 2.0), Interval(1.0, 2.0));
  EXPECT_LE(a.lo, std::atan2(1.0, 2.0));
  EXPECT_GT(a.lo, 0.46);
  EXPECT_GE(a.hi, std::atan2(2.0, 1.0));
  EXPECT_LT(a.hi, 1.11);
}

TEST(Interval, ComparisonsLogicAndSelect) {
  auto v = [](const Interval& r) { return r.lo == r.hi ? r.lo : -1.0; };  // -1: undecided
  EXPECT_EQ(v(applyOp(Op::Lt, Interval(0.0, 1.0), Interval(2.0, 3.0))), 1.0);
  EXPECT_EQ(v(applyOp(Op::Lt, Interval(0.0, 2.0), Interval(2.0, 3.0))), -1.0);
  EXPECT_EQ(v(applyOp(Op::Le, Interval(0.0, 2.0), Interval(2.0, 3.0))), 1.0);
  EXPECT_EQ(v(applyOp(Op::Gt, Interval(0.0, 2.0), Interval(2.0, 3.0))), 0.0);
  EXPECT_EQ(v(applyOp(Op::Eq, Interval(2.0), Interval(2.0))), 1.0);
  EXPECT_EQ(v(applyOp(Op::Ne, Interval(0.0, 1.0), Interval(2.0, 3.0))), 1.0);
  EXPECT_EQ(v(applyOp(Op::Le, Interval::everything(), Interval(kInf))), -1.0);  // NaN <= inf is false
  EXPECT_EQ(v(applyOp(Op::And, Interval(1.0, 2.0), Interval(-3.0, -1.0))), 1.0);
  EXPECT_EQ(v(applyOp(Op::And, Interval(0.0), Interval(-3.0, 1.0))), 0.0);
  EXPECT_EQ(v(applyOp(Op::Or, Interval(0.0), Interval(-3.0, 1.0))), -1.0);
  EXPECT_EQ(v(applyOp(Op::Not, Interval(0.0))), 1.0);
  Interval s = applyOp(Op::Select, Interval(1.0, 2.0), Interval(5.0), Interval(7.0));
  EXPECT_EQ(v(s), 5.0);
  EXPECT_EQ(v(applyOp(Op::Select, Interval(0.0), Interval(5.0), Interval(7.0))), 7.0);
  s = applyOp(Op::Select, Interval(0.0, 1.0), Interval(5.0), Interval(7.0));
  EXPECT_EQ(s.lo, 5.0);
  EXPECT_EQ(s.hi, 7.0);
}

// Every op over many random intervals: each sampled point's scalar value is enclosed.
TEST(Interval, EveryOpIsSoundOnRandomIntervals) {
  std::mt19937_64 rng(20261126);
  const int powExps[] = {-5, -4, -3, -2, -1, 1, 2, 3, 4, 7, 10};
  int checked = 0;
  for (int o = int(Op::Neg); o < int(Op::Field); ++o) {  // Op::Field needs its object (volume_spline_test)
    const Op op = Op(o);
    const int arity = opArity(op);
    for (int trial = 0; trial < 3000; ++trial) {
      Interval a = randomInterval(rng), b = randomInterval(rng), c = randomInterval(rng);
      if (op == Op::Select && rng() % 2) a = Interval(rng() % 2 ? 0.0 : 1.0, rng() % 2 ? 0.0 : 1.0);
      if (a.lo > a.hi) std::swap(a.lo, a.hi);
      const double imm = op == Op::PowI ? powExps[rng() % (sizeof(powExps) / sizeof(int))] : 0.0;
      const Interval r = applyOp(op, a, b, c, imm);
      ASSERT_LE(r.lo, r.hi) << opName(op);
      for (int k = 0; k < 16; ++k) {
        double x = randomPoint(a, rng), y = arity > 1 ? randomPoint(b, rng) : 0.0;
        double z = arity > 2 ? randomPoint(c, rng) : 0.0;
        ASSERT_TRUE(encloses(r, applyOp(op, x, y, z, imm)))
            << opName(op) << " imm " << imm << " at (" << x << ", " << y << ", " << z << ") over [" << a.lo
            << ", " << a.hi << "] [" << b.lo << ", " << b.hi << "] [" << c.lo << ", " << c.hi << "]";
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000000);
}

namespace {

// A random expression DAG over x0..x2 using every op; sub-expressions are reused so the
// result is a DAG, not just a tree.
class RandomDag {
 public:
  explicit RandomDag(uint64_t seed) : rng_(seed) {}

  Expr make(int depth) {
    if (depth == 0 || rng_() % 16 == 0) return leaf();
    if (!made_.empty() && rng_() % 8 == 0) return made_[rng_() % made_.size()];
    Op op = Op(int(Op::Neg) + rng_() % (int(Op::Field) - int(Op::Neg)));
    if (op == Op::Copy) op = Op::Select;  // Copy exists only in pruned tapes
    Expr e;
    if (op == Op::PowI) {
      static const int exps[] = {-3, -2, -1, 2, 3, 4, 5};
      e = Expr::powi(make(depth - 1), exps[rng_() % 7]);
    } else if (opArity(op) == 1) {
      e = Expr::make(op, make(depth - 1));
    } else if (opArity(op) == 2) {
      e = Expr::make(op, make(depth - 1), make(depth - 1));
    } else {
      e = Expr::make(op, make(depth - 1), make(depth - 1), make(depth - 1));
    }
    made_.push_back(e);
    return e;
  }

  std::mt19937_64& rng() { return rng_; }

 private:
  Expr leaf() {
    static const double consts[] = {0.0, 1.0, -1.0, 0.5, 2.0, -2.5, 3.0, kPi / 2};
    if (rng_() % 3 == 0) return Expr(consts[rng_() % 8]);
    return Expr::x(uint32_t(rng_() % 3));
  }
  std::mt19937_64 rng_;
  std::vector<Expr> made_;
};

Interval randomBoxSide(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  static const double widths[] = {0.0, 1e-3, 0.1, 0.5, 1.0, 4.0};
  double lo = 6 * u(rng) - 3;
  if (rng() % 4 == 0) lo = std::round(lo);  // integer or zero endpoints
  return {lo, lo + widths[rng() % 6]};
}

bool sameValue(double a, double b) { return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, 8) == 0; }

}  // namespace

// Whole random DAGs: every point of a box evaluates inside the box's interval, and the tape
// pruned for the box gives the same bits as the full tape at those points.
TEST(Interval, RandomDagsAreSoundAndPruningIsExact) {
  RandomDag gen(7);
  auto& rng = gen.rng();
  PointEvaluator pe;
  IntervalEvaluator ie;
  int boxes = 0, prunedBoxes = 0;
  for (int model = 0; model < 2000; ++model) {
    Expr e = gen.make(7);
    TapePtr tape = Tape::compile(e, 3);
    for (int b = 0; b < 4; ++b) {
      Interval box[3] = {randomBoxSide(rng), randomBoxSide(rng), randomBoxSide(rng)};
      const Interval r = ie.eval(*tape, box);
      ASSERT_LE(r.lo, r.hi);
      TapePtr pruned = ie.pruned(tape);
      if (pruned.get() != tape.get()) ++prunedBoxes;
      ++boxes;
      for (int k = 0; k < 32; ++k) {
        double p[3];
        for (int i = 0; i < 3; ++i) p[i] = randomPoint(box[i], rng);
        const double v = pe.eval(*tape, p);
        ASSERT_TRUE(encloses(r, v)) << toString(e) << " at (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
        const double w = pe.eval(*pruned, p);
        ASSERT_TRUE(sameValue(v, w)) << toString(e) << ": full " << v << " pruned " << w;
      }
    }
  }
  EXPECT_EQ(boxes, 8000);
  EXPECT_GT(prunedBoxes, 100);  // choices do get decided, so the exactness check is exercised
}

// The evaluator sees that both operands of x * x are one register and bounds it as x^2.
TEST(Interval, EvaluatorBoundsSelfProductAsSquare) {
  Expr x = Expr::x(0);
  TapePtr t = Tape::compile(x * x - 1.0, 1);
  IntervalEvaluator ie;
  Interval box[1] = {{-1.0, 2.0}};
  Interval r = ie.eval(*t, box);
  EXPECT_LE(r.lo, -1.0);
  EXPECT_GT(r.lo, -1.0 - 1e-12);  // not -3, as [-1, 2] * [-1, 2] would give
  EXPECT_GE(r.hi, 3.0);
  EXPECT_LT(r.hi, 3.0 + 1e-12);
}

// A constant folded to NaN lands in a uniform register; the evaluator must treat it as
// everything(), never as an interval with NaN bounds.
TEST(Interval, NaNConstantIsEverything) {
  Expr nanConst = fmod(Expr(1.0), Expr(0.0));
  ASSERT_TRUE(nanConst.isConst());
  TapePtr t = Tape::compile(Expr::x(0) + nanConst, 1);
  IntervalEvaluator ie;
  Interval box[1] = {{0.0, 1.0}};
  EXPECT_TRUE(isEverything(ie.eval(*t, box)));
  TapePtr c = Tape::compile(nanConst, 1);
  EXPECT_TRUE(isEverything(ie.eval(*c, box)));
}
