// The min/max form (frep/expressions/min_max_form.h): R-functions in sign position become
// min/max with the same sign everywhere; value positions are left alone; the extremum searches
// run their operands in this form and keep the set while spending far fewer evaluations.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/expressions/min_max_form.h"
#include "frep/extremum/extremum.h"
#include "frep/primitives/ops.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

// Random solids from spheres and half-spaces by R-functions of random a in (-1, 1], negation,
// positive scaling and selects: every R-function is in sign position.
Expr randomRModel(std::mt19937_64& rng, int depth) {
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  if (depth == 0 || rng() % 5 == 0) {
    if (rng() % 3 == 0) return 0.2 * u(rng) - u(rng) * X - u(rng) * Y - u(rng) * Z;
    const double cx = u(rng), cy = u(rng), cz = u(rng), r = 0.3 + 0.3 * std::fabs(u(rng));
    return r * r - square(X - cx) - square(Y - cy) - square(Z - cz);
  }
  const double a = std::uniform_real_distribution<double>(-0.9, 1.0)(rng);
  Expr p = randomRModel(rng, depth - 1), q = randomRModel(rng, depth - 1);
  switch (rng() % 5) {
    case 0: return rIntersection(p, q, a);
    case 1: return rUnion(p, q, a);
    case 2: return rSubtraction(p, q, a);
    case 3: return 2.5 * rAnd(p, -q, 0.0);
    default: return select(gt(X, u(rng)), rOr(p, q, 0.0), p / 3.0);
  }
}

int signOf(double v) { return v > 0 ? 1 : v < 0 ? -1 : 0; }

}  // namespace

TEST(MinMaxForm, SameSignAsTheRFunctionsEverywhere) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  PointEvaluator pe;
  size_t compared = 0;
  for (int m = 0; m < 40; ++m) {
    const Expr e = randomRModel(rng, 6);
    const Expr f = minMaxForm(e);
    TapePtr te = Tape::compile(e, 3), tf = Tape::compile(f, 3);
    for (int i = 0; i < 2000; ++i) {
      double x[3] = {u(rng), u(rng), u(rng)};
      const double ve = pe.eval(*te, x), vf = pe.eval(*tf, x);
      if (std::fabs(vf) < 1e-9) continue;  // R-functions round to 0 when |f1| << |f2|
      ASSERT_EQ(signOf(ve), signOf(vf)) << "model " << m << " at " << x[0] << "," << x[1] << "," << x[2];
      ++compared;
    }
    for (const Instr& ins : tf->code()) EXPECT_TRUE(ins.op != Op::RAnd && ins.op != Op::ROr);
  }
  EXPECT_GT(compared, 70000u);
}

TEST(MinMaxForm, ValuePositionsAreLeftAlone) {
  const Expr s1 = 1.0 - square(X) - square(Y), s2 = 0.5 - square(X - 0.5);
  const Expr offset = rIntersection(s1, s2, 0.0) + 0.1;  // a sum uses the value
  EXPECT_TRUE(minMaxForm(offset).same(offset));
  EXPECT_FALSE(hasSignPositionRFunction(offset));
  const Expr blend = rIntersection(s1, s2, 0.0) * rUnion(s1, s2, 0.0);  // product of fields
  EXPECT_TRUE(minMaxForm(blend).same(blend));
  const Expr negScale = -2.0 * rIntersection(s1, s2, 0.0);  // negative constant: the value's sign flips
  EXPECT_TRUE(minMaxForm(negScale).same(-2.0 * min(s1, s2)) || minMaxForm(negScale).same(negScale));
  EXPECT_TRUE(minMaxForm(rIntersection(s1, s2, 0.0)).same(min(s1, s2)));
  EXPECT_TRUE(minMaxForm(-rUnion(s1, -s2, 0.5)).same(-max(s1, -s2)));
}

TEST(MinMaxForm, SlabProductsWithConstantSumBecomeMins) {
  const Expr slab = (X + 1.0) * (1.0 - X);  // p + q = 2: never both negative
  EXPECT_TRUE(minMaxForm(slab).same(min(X + 1.0, 1.0 - X)));
  const Expr crossed = (X - 1.0) * (-1.0 - X);  // p + q = -2: both negative on |x| < 1
  EXPECT_TRUE(minMaxForm(crossed).same(crossed));
  const Expr notAffineSum = (X - 1.0) * (X - 2.0);  // p + q = 2x - 3
  EXPECT_TRUE(minMaxForm(notAffineSum).same(notAffineSum));
  const Expr mixed = (X + 2.0 * Y - 0.5) * (1.5 - X - 2.0 * Y);  // a slab across a diagonal
  EXPECT_TRUE(minMaxForm(mixed).same(min(X + 2.0 * Y - 0.5, 1.5 - X - 2.0 * Y)));
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-3, 3);
  PointEvaluator pe;
  TapePtr a = Tape::compile(mixed, 3), b = Tape::compile(minMaxForm(mixed), 3);
  for (int i = 0; i < 5000; ++i) {
    double x[3] = {u(rng), u(rng), u(rng)};
    EXPECT_EQ(signOf(pe.eval(*a, x)), signOf(pe.eval(*b, x)));
  }
}

// A non-convex slab written with HyperFun's sqrt R-functions (hfBlock's (sx &0 sy) &0 sz and
// '\') summed with a ball: the same set as its R-function search, at a fraction of the cost.
TEST(MinMaxForm, MinkowskiSumOfRFunctionOperandsKeepsTheSetAndIsCheaper) {
  auto block = [](double x0, double y0, double z0, double dx, double dy, double dz) {
    return rAnd(rAnd((X - x0) * (x0 + dx - X), (Y - y0) * (y0 + dy - Y), 0.0), (Z - z0) * (z0 + dz - Z), 0.0);
  };
  const Expr slab = rSubtraction(block(-1, -1, -0.25, 2, 2, 0.5), block(-0.2, -0.2, -1, 1.5, 1.5, 2), 0.0);
  const Expr ball = 0.09 - square(X) - square(Y) - square(Z);
  Bounds bb{{-0.3, -0.3, -0.3}, {0.3, 0.3, 0.3}};
  MinkowskiOptions fast, slow;
  slow.minMaxOperands = false;
  TapePtr tf = Tape::compile(minkowskiSum(slab, ball, 3, bb, fast), 3);
  TapePtr ts = Tape::compile(minkowskiSum(slab, ball, 3, bb, slow), 3);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.4, 1.4);
  PointEvaluator pf, ps;
  uint64_t evalsFast = 0, evalsSlow = 0;
  int compared = 0;
  for (int i = 0; i < 150; ++i) {
    double x[3] = {u(rng), u(rng), 0.6 * u(rng)};
    resetExtremumCounters();
    const double vf = pf.eval(*tf, x);
    evalsFast += extremumCounters().pointEvals + extremumCounters().intervalEvals;
    resetExtremumCounters();
    const double vs = ps.eval(*ts, x);
    evalsSlow += extremumCounters().pointEvals + extremumCounters().intervalEvals;
    if (std::fabs(vf) < 2e-3 || std::fabs(vs) < 2e-3) continue;  // within the searches' tolerance
    EXPECT_EQ(signOf(vf), signOf(vs)) << x[0] << "," << x[1] << "," << x[2];
    ++compared;
  }
  EXPECT_GT(compared, 100);
  std::printf("[figures] body evaluations: min/max form %llu, R-functions %llu (%.1fx)\n",
              (unsigned long long)evalsFast, (unsigned long long)evalsSlow, double(evalsSlow) / double(evalsFast));
  EXPECT_LT(3 * evalsFast, evalsSlow);
}
