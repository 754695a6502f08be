// The evaluators' own sin/cos (sin_cos.h) against long double libm: the documented error bound
// (kOwnTrigUlps ulps + kOwnTrigAbsErr) on dense, random and hardest (next to multiples of pi/2)
// arguments; libm's bits beyond the range; the interval extension containing every value the
// point evaluator gives in random boxes; point, batch and gradient giving the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/expr.h"
#include "frep/expressions/sin_cos.h"

using namespace frep;

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// ulp of a double of magnitude |v| (subnormals: 2^-1074).
double ulpOf(double v) {
  v = std::fabs(v);
  if (v < std::numeric_limits<double>::min()) return std::numeric_limits<double>::denorm_min();
  return std::ldexp(1.0, std::ilogb(v) - 52);
}

struct ErrorStats {
  double maxUlps = 0;      // |own - ref| / ulp(ref), where the absolute part is not needed
  size_t overBound = 0;    // points where the documented bound fails
  void add(double own, long double ref) {
    const double err = double(std::fabs((long double)own - ref));
    const double u = ulpOf(double(ref));
    if (err > kOwnTrigUlps * u + kOwnTrigAbsErr) ++overBound;
    if (std::fabs(double(ref)) > 1e-6) maxUlps = std::max(maxUlps, err / u);
  }
};

void check(double x, ErrorStats& s, ErrorStats& c) {
  s.add(ownSin(x), sinl((long double)x));
  c.add(ownCos(x), cosl((long double)x));
}

TEST(OwnSinCos, DenseArgumentsWithinTheBound) {
  ErrorStats s, c;
  for (int i = -400000; i <= 400000; ++i) check(i * 2.5e-5, s, c);  // [-10, 10]
  EXPECT_EQ(s.overBound, 0u);
  EXPECT_EQ(c.overBound, 0u);
  EXPECT_LE(s.maxUlps, double(kOwnTrigUlps));
  EXPECT_LE(c.maxUlps, double(kOwnTrigUlps));
  // the Taylor polynomials are near-correctly rounded: over 0.5 ulp means something broke
  std::printf("dense [-10, 10]: max error sin %.3f ulp, cos %.3f ulp\n", s.maxUlps, c.maxUlps);
  EXPECT_GT(s.maxUlps, 0.5);  // not correctly rounded (a sign that the reference is independent)
}

TEST(OwnSinCos, RandomArgumentsOverTheWholeRange) {
  std::mt19937_64 rng(17);
  ErrorStats s, c;
  for (int i = 0; i < 400000; ++i) {
    // log-uniform magnitude from 2^-60 to the range limit, both signs
    const double mag = std::ldexp(1.0, -60 + int(rng() % 80));
    const double x = std::uniform_real_distribution<double>(-1.0, 1.0)(rng) * std::min(mag, kOwnTrigLimit);
    check(x, s, c);
  }
  std::printf("random |x| <= 2^19: max error sin %.3f ulp, cos %.3f ulp\n", s.maxUlps, c.maxUlps);
  EXPECT_EQ(s.overBound, 0u);
  EXPECT_EQ(c.overBound, 0u);
  EXPECT_LE(s.maxUlps, double(kOwnTrigUlps));
  EXPECT_LE(c.maxUlps, double(kOwnTrigUlps));
}

TEST(OwnSinCos, NextToMultiplesOfHalfPi) {
  // Where sin or cos is near zero the reduction's absolute error shows: the doubles nearest to
  // k pi/2 and their neighbours, k up to the range limit.
  std::mt19937_64 rng(18);
  ErrorStats s, c;
  const long double halfPi = 1.5707963267948966192313216916397514L;
  for (int i = 0; i < 100000; ++i) {
    const long long k = (i < 1000) ? i : (long long)(rng() % (long long)(kOwnTrigLimit / 1.5707963));
    double x = double(k * halfPi) * ((rng() & 1) ? 1 : -1);
    for (int step = 0; step < 3; ++step, x = std::nextafter(x, 0.0))
      if (std::fabs(x) <= kOwnTrigLimit) check(x, s, c);
  }
  EXPECT_EQ(s.overBound, 0u);
  EXPECT_EQ(c.overBound, 0u);
}

TEST(OwnSinCos, SpecialValuesAndBeyondTheRange) {
  EXPECT_TRUE(sameBits(ownSin(-0.0), -0.0));
  EXPECT_TRUE(sameBits(ownSin(0.0), 0.0));
  EXPECT_EQ(ownCos(-0.0), 1.0);
  EXPECT_EQ(ownSin(1e-300), 1e-300);
  EXPECT_TRUE(std::isnan(ownSin(std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(ownCos(-std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(ownSin(std::numeric_limits<double>::quiet_NaN())));
  for (double x : {std::nextafter(kOwnTrigLimit, 1e300), 1e6, -3e7, 1e22, -1e300}) {
    EXPECT_TRUE(sameBits(ownSin(x), std::sin(x))) << x;
    EXPECT_TRUE(sameBits(ownCos(x), std::cos(x))) << x;
  }
  // never outside [-1, 1] (the interval extension clamps there)
  for (int i = 0; i <= 200000; ++i) {
    const double x = i * 1e-5;
    EXPECT_LE(std::fabs(ownSin(x)), 1.0);
    EXPECT_LE(std::fabs(ownCos(x)), 1.0);
  }
  double s, c;
  ownSinCos(2.5, s, c);
  EXPECT_TRUE(sameBits(s, ownSin(2.5)) && sameBits(c, ownCos(2.5)));
}

TEST(OwnSinCos, IntervalContainsEveryPointValue) {
  // Random boxes: small ones next to extrema and zeros, wide ones, far from the origin; every
  // sample's own value (what the point evaluator gives) lies in the interval.
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  size_t samples = 0;
  for (int b = 0; b < 20000; ++b) {
    const double centre = (b % 3 == 0) ? std::round(u(rng) * 2e5) * 1.5707963267948966
                                       : (u(rng) * 2 - 1) * std::ldexp(1.0, int(rng() % 22));
    const double width = std::ldexp(u(rng), -int(rng() % 50));
    const Interval box{centre - width, centre + width};
    for (Op op : {Op::Sin, Op::Cos}) {
      const Interval r = applyOp(op, box);
      auto f = [&](double x) { return applyOp(op, x, 0.0, 0.0, 0.0); };
      for (int k = 0; k <= 64; ++k) {
        const double x = k == 64 ? box.hi : box.lo + (box.hi - box.lo) * (k / 64.0);
        ASSERT_TRUE(r.contains(f(x))) << (op == Op::Sin ? "sin" : "cos") << " [" << box.lo << ", " << box.hi
                                      << "] at " << x << ": " << f(x) << " not in [" << r.lo << ", " << r.hi << "]";
        ++samples;
      }
      // neighbours of the endpoints, where the rounding matters most
      for (double x : {std::nextafter(box.lo, box.hi), std::nextafter(box.hi, box.lo)})
        ASSERT_TRUE(r.contains(f(x)));
    }
  }
  EXPECT_GT(samples, 2000000u);
}

TEST(OwnSinCos, IntervalStaysTight) {
  // The widening is a few ulps, not more: a point box around 1 keeps sin within 3e-15 (27 ulps).
  const Interval r = applyOp(Op::Sin, Interval{1.0, 1.0});
  EXPECT_LT(r.hi - r.lo, 3e-15);
  EXPECT_TRUE(r.contains(ownSin(1.0)));
  const Interval z = applyOp(Op::Sin, Interval{-1e-20, 1e-20});
  EXPECT_LT(z.hi - z.lo, 1e-18);
}

TEST(OwnSinCos, PointBatchGradientSameBits) {
  const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  const Expr e = sin(8 * X) * cos(8 * Y) + sin(8 * Y) * cos(8 * Z) + sin(8 * Z) * cos(8 * X) + cos(X * Y);
  TapePtr t = Tape::compile(e, 3);
  constexpr size_t B = BatchEvaluator<double>::kBatch;
  PointEvaluator pe;
  GradientEvaluator ge;
  BatchEvaluator<double> be;
  BatchEvaluator<float> bf;
  be.reserve(*t);
  bf.reserve(*t);
  std::mt19937_64 rng(20);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<double> p(B * 3);
  for (int rep = 0; rep < 20; ++rep) {
    for (size_t k = 0; k < B; ++k)
      for (uint32_t i = 0; i < 3; ++i) {
        p[k * 3 + i] = (rep == 19 && k == 5) ? 1e7 : u(rng);  // one batch with a lane beyond range
        be.in(i)[k] = p[k * 3 + i];
        bf.in(i)[k] = float(p[k * 3 + i]);
      }
    const double* out = be.eval(*t, B);
    const float* outF = bf.eval(*t, B);
    for (size_t k = 0; k < B; ++k) {
      const double* x = &p[k * 3];
      const double ref = pe.eval(*t, x);
      double g[3];
      ASSERT_TRUE(sameBits(out[k], ref)) << "lane " << k;
      ASSERT_TRUE(sameBits(ge.eval(*t, x, g), ref)) << "lane " << k;
      // d/dx of the sum, from the same own cos/sin the gradient evaluator uses
      const double dx = 8 * ownCos(8 * x[0]) * ownCos(8 * x[1]) - 8 * ownSin(8 * x[2]) * ownSin(8 * x[0]) -
                        x[1] * ownSin(x[0] * x[1]);
      EXPECT_NEAR(g[0], dx, 1e-12 * (1 + std::fabs(dx)));
      if (!(rep == 19 && k == 5)) {  // (float: x*y of the 1e7 lane rounds)
        EXPECT_NEAR(double(outF[k]), ref, 3e-5);
      }
    }
  }
}

// ulps of float of magnitude |v|.
double ulpOfFloat(double v) {
  v = std::fabs(v);
  if (v < double(std::numeric_limits<float>::min())) return double(std::numeric_limits<float>::denorm_min());
  return std::ldexp(1.0, std::ilogb(v) - 23);
}

TEST(OwnSinCos, FloatLanesWithinTheirBound) {
  // The float batch path's own functions: 2 float ulps + 1e-9 absolute, dense, random, every
  // float in [1, 1.0001] * 2^k, beyond the float range (the double functions rounded).
  std::mt19937_64 rng(21);
  double maxUlps = 0;
  size_t over = 0, n = 0;
  auto check = [&](float x) {
    float s, c;
    ownSinCosFloat(x, s, c);
    const long double rs = sinl((long double)x), rc = cosl((long double)x);
    for (auto [v, ref] : {std::pair<float, long double>{s, rs}, {c, rc}}) {
      const double err = double(std::fabs((long double)v - ref)), u = ulpOfFloat(double(ref));
      if (err > 2 * u + 1e-9) ++over;
      if (std::fabs(double(ref)) > 1e-3) maxUlps = std::max(maxUlps, err / u);
      ++n;
    }
  };
  for (int i = -400000; i <= 400000; ++i) check(float(i * 2.5e-5));
  for (int i = 0; i < 400000; ++i)
    check(float(std::uniform_real_distribution<double>(-1.0, 1.0)(rng) * std::ldexp(1.0, int(rng() % 16))));
  for (int e = -20; e <= 14; ++e)
    for (float x = std::ldexp(1.0f, e), end = x * 1.0001f; x <= end; x = std::nextafter(x, 2 * end)) check(-x);
  for (float x : {8192.0f, 8193.0f, 1e5f, -3e7f}) check(x);
  std::printf("float lanes: max error %.3f float ulp over %zu values\n", maxUlps, n);
  EXPECT_EQ(over, 0u);
  float s, c;
  ownSinCosFloat(-0.0f, s, c);
  EXPECT_TRUE(std::signbit(s) && s == 0.0f && c == 1.0f);
}

}  // namespace
